"""The run's settings that ``faultgen monitor`` keeps beside its page (``OUT/settings.json``) and
``faultgen report`` reads back: written as the run had them, read back only with the keys and
values a run writes (:func:`check_settings`), so a planted file cannot pass a value the page's
arithmetic would choke on."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, is_dataclass
from pathlib import Path

from faultgen import inputs
from faultgen.monitor import scoring
from faultgen.monitor.state import SCALE_PRIOR_KEYS

#: The run's settings beside it (what ``faultgen report`` builds the page again with).
SETTINGS = "settings.json"
#: Size bound of a settings file read back (a few hundred bytes written).
SETTINGS_MAX_BYTES = 64 * 2**10

def settings_dict(settings, extra: dict) -> dict:
    """``settings`` (a dataclass or a dict) with ``extra``, its scalar values only, as written to the file."""
    base = asdict(settings) if is_dataclass(settings) else dict(settings or {})
    kept = {**base, **extra}
    return {k: v for k, v in kept.items() if isinstance(v, (str, int, float, bool)) or v is None}


def read_settings(folder: str | Path) -> dict:
    """The run's settings kept in ``OUT/settings.json`` (by :func:`faultgen.monitor.page.write`); for a folder written
    before it, those of the monitors' state (``OUT/.state/<unit>.json``, their ``settings``); an
    empty dict when neither is there: the page then leaves them and the false-alarm statement out.

    Raises
    ------
    ValueError
        A settings file that is not a JSON object, is too large, or a link out of the folder; a
        key or value no run writes (:func:`check_settings`).
    """
    folder = Path(folder)
    path = folder / SETTINGS
    max_bytes = SETTINGS_MAX_BYTES
    key = None
    if not (path.exists() or path.is_symlink()):
        states = sorted((folder / ".state").glob("*.json")) if (folder / ".state").is_dir() else []
        if not states:
            return {}
        from faultgen.monitor.state import STATE_MAX_BYTES

        path, max_bytes, key = states[0], STATE_MAX_BYTES, "settings"
    if not inputs.inside(path, folder):
        raise ValueError(f"{path}: a link leading outside {folder}; it is not read")
    try:
        document = json.loads(inputs.read_text(path, "monitor settings", max_bytes))
    except (ValueError, RecursionError) as err:
        raise ValueError(f"{path}: not a monitor's settings ({str(err)[:80]})") from None
    if key is not None and isinstance(document, dict):
        document = document.get(key)
    if isinstance(document, dict):
        return check_settings(document, path)
    raise ValueError(f"{path}: not a monitor's settings (expected a JSON object)")


def _setting_count(low: int, high: int):
    return lambda v: isinstance(v, int) and not isinstance(v, bool) and low <= v <= high


def _setting_number(low: float, high: float, top: bool):
    return lambda v: (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                      and low < v and (v <= high if top else v < high))


def _setting_shown(value) -> str:
    """A JSON value for a message, cut to 40 characters."""
    text = json.dumps(value)
    return text if len(text) <= 40 else f"{text[:40]}... ({len(text)} characters)"


def _setting_text(v) -> bool:
    return isinstance(v, str) and len(v) <= 4096


#: Each key of a settings file (a run's ``settings.json``, or the ``settings`` of a state written
#: before it) and the values a run writes there: a check, and what is expected (what a refusal says).
SETTING_VALUES = {
    "protocol": (lambda v: v in scoring.PROTOCOLS, f"one of {', '.join(scoring.PROTOCOLS)}"),
    "train": (_setting_count(scoring.MIN_TRAIN, scoring.MAX_LOGS),
              f"a whole number of logs {scoring.MIN_TRAIN}..{scoring.MAX_LOGS}"),
    "alpha": (_setting_number(0.0, 0.5, False), "a significance level in (0, 0.5)"),
    "variance": (_setting_number(0.0, 1.0, True), "a share of the PCA variance in (0, 1]"),
    "persistence": (_setting_count(1, scoring.MAX_LOGS), f"a whole number of logs 1..{scoring.MAX_LOGS}"),
    "wear_limit": (_setting_number(0.0, scoring.MAX_WEAR_LIMIT, True), f"a wear in (0, {scoring.MAX_WEAR_LIMIT:g}] %"),
    "twin_temperature": (lambda v: isinstance(v, bool), "true or false"),
    **{name: (_setting_number(0.0, math.inf, False), "a finite number above 0") for name in SCALE_PRIOR_KEYS},
    **{name: (_setting_text, "a text of at most 4096 characters") for name in ("robot", "logs", "model", "format")},
}


def check_settings(document: dict, path: str | Path) -> dict:
    """``document``, a settings file's object, after checking each key is one a run writes and its
    value in the range a run writes (:data:`SETTING_VALUES`; a key may be absent).

    Raises
    ------
    faultgen.inputs.InputError
        Naming ``path``, the key and what was expected: an unknown key, a value of another type or
        out of range (a negative ``train``, an infinite ``alpha``, ``persistence`` of 10^400).
    """
    for key, value in document.items():
        if key not in SETTING_VALUES:
            raise inputs.InputError(f"{path}: key {str(key)[:40]!r} is not a monitor setting (expected only "
                                    f"{', '.join(SETTING_VALUES)}); write the file again with `faultgen monitor`")
        valid, expected = SETTING_VALUES[key]
        if not valid(value):
            raise inputs.InputError(f"{path}: {key} = {_setting_shown(value)}; expected {expected} (as a monitor run "
                                    "writes it)")
    return dict(document)
