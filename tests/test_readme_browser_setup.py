"""The README says to install the browser the test suite needs before it shows the command that runs
the suite (issue 88, item 6: the `apt-get install chromium` line came only after the test command)."""

from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_the_readme_installs_chromium_before_it_runs_the_tests():
    text = " ".join(README.read_text().split())
    install = text.find("apt-get install chromium chromium-driver")
    run = text.find("-m pytest")
    assert install != -1 and run != -1, "the README names both the browser's install and the test command"
    assert install < run, "the README installs chromium only after it runs the tests"
