"""The ``key=value,...`` options at the end of a wear spec (``--wear 2:exp4:50:onset=40``) and of a
fault spec (``--fault backlash:2:width:0.01:kind=exp4,onset=40``): one reader for both, so both
refuse a malformed option with the same words."""

from __future__ import annotations

from collections.abc import Callable, Iterator


def key_values(text: str, fail: Callable[[str], Exception]) -> Iterator[tuple[str, str]]:
    """The options of ``text`` (``"key=value,key=value"``) in their order, as (key, value) strings
    with the white space around each stripped; a key given twice comes twice (the caller's last
    one wins). Read lazily, so an option's value can be refused before a later option is read.

    Parameters
    ----------
    text : str
        The spec's last ``:``-separated field, e.g. ``"kind=exp4, onset=40"``.
    fail : callable
        ``fail(reason) -> Exception``: the caller's error, which quotes its whole spec and form.

    Raises
    ------
    Exception
        ``fail("option 'x' is not key=value")`` for an option without ``=``, key or value.
    """
    for option in text.split(","):
        key, sep, value = (s.strip() for s in option.partition("="))
        if not sep or not key or not value:
            raise fail(f"option {option!r} is not key=value")
        yield key, value
