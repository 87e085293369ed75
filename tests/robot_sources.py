"""Shared by the tests of hostile robot descriptions (test_hostile_robots.py, test_robot_bounds.py):
`faultgen robots add` run through the command line and checked to refuse as promised."""

from typer.testing import CliRunner

from faultgen.cli import app


def refused(tmp_path, source, *words, extra=()):
    """`faultgen robots add robot --from SOURCE -o TMP/out/robot [extra]`: exit 2, one line
    ``error: ...`` holding every one of ``words``, and nothing written (no robot folder, no
    staging folder). Returns the line."""
    out = tmp_path / "out" / "robot"
    result = CliRunner().invoke(app, ["robots", "add", "robot", "--from", str(source), "-o", str(out),
                                      *map(str, extra)])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for word in words:
        assert word in lines[0], lines[0]
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())
    return lines[0]
