"""What a sweep or fleet raises when it cannot finish or start: each error carries the command
line's exit code (:class:`faultgen.cli.base.Command` uses it) and a message that says what to do."""

from __future__ import annotations


class SweepError(RuntimeError):
    """A sweep could not finish; the message says what to do. Finished runs are kept."""

    #: The command line's exit code for it (faultgen.cli.base.Command): a run failed.
    exit_code = 1


class SweepRefused(SweepError):
    """A sweep refused to start (its output exists, or another sweep is writing it); nothing ran."""

    exit_code = 2


class SweepInterrupted(SweepError):
    """A sweep was interrupted (Ctrl-C); the message says how many runs are kept and how to resume."""

    exit_code = 130  # as a shell reports a process ended by SIGINT (143 for SIGTERM)
    message_prefix = ""  # a report of what was kept, not an error

    def __init__(self, message: str, exit_code: int = 130) -> None:
        super().__init__(message)
        self.exit_code = exit_code
