"""``python -m faultgen.cli``: the ``faultgen`` command."""

import sys

from faultgen.bench import profile

profile.restart_early(sys.argv[1:])  # `bench make` of a profiled version: restarted before the commands load

from faultgen.cli import app  # noqa: E402

app()
