"""``python -m faultgen.cli``: the ``faultgen`` command."""

from faultgen.cli import app

app()
