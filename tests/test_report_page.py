"""The monitor's fleet report (``OUT/report.html``, faultgen.monitor.page; issue 58) opened in a
real browser: Debian's headless Chromium driven by Selenium (chromedriver), both from the
package registry (`.ci/run` installs them with apt-get; Selenium is pointed at them, so it never
downloads a browser or a driver of its own). The page comes from a small monitor output made
directly: :class:`~faultgen.monitor.history.UnitHistory` records fed synthetic residuals (a worn
unit, a healthy one, one whose alarm a repair closed, one still learning, one never scored, and
one named like an HTML injection), written by the monitor's own CSV writers.

With ``FAULTGEN_SCREENSHOT=1`` the test also saves its screenshot of the page as
docs/report-page.png (docs/analysis.md shows it)."""

from __future__ import annotations

import csv
import html
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.monitor import page, report, run_settings, steps, tables
from faultgen.monitor.loop import UnitStatus
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.scoring import Settings

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM, CHROMEDRIVER = Path("/usr/bin/chromium"), Path("/usr/bin/chromedriver")
SETTINGS = Settings(train=10, persistence=3, alpha=0.01, wear_limit=5.0)
N_AXES, N_FEATURES = 3, 9
HOSTILE = "press<img src=x onerror=alert(1)>"  # a folder name a stranger's LOGS may hold
UNITS = ("weld-07", "weld-02", "paint-11", HOSTILE, "=new-cell", "spare-01")


def _feed(monitor: UnitHistory, days: int, wear, seed: int, repair: int | None = None) -> None:
    """``days`` daily logs: noise (1 per feature) plus ``wear(day)`` % along axis 2's signature;
    a repair of axis 2 before day ``repair``."""
    rng = np.random.default_rng(seed)
    for day in range(days):
        if day == repair:
            steps.maintenance(monitor, f"2026-03-{day + 1:02d} 06:00", "repair", 2)
        residual = rng.standard_normal(N_FEATURES) + wear(day) * monitor.stages.baseline.signatures[1]
        steps.add(monitor, f"2026-03-{day + 1:02d}", residual, float("nan"), 0.0)


def make_tables() -> tuple[list, list[UnitHistory]]:
    """The tables (units.csv, alarms.csv, scores.csv) of :data:`UNITS` in memory, and their monitors."""
    signatures = np.random.default_rng(0).standard_normal((N_AXES, N_FEATURES))
    monitors = [steps.start(name, SETTINGS, N_AXES, signatures) for name in UNITS[:5]]
    _feed(monitors[0], 30, lambda d: max(0.0, d - 14) * 1.5, seed=1)  # wears from day 15
    _feed(monitors[1], 30, lambda d: 0.0, seed=2)
    _feed(monitors[2], 30, lambda d: 0.0 if d < 12 or d >= 20 else 25.0, seed=3, repair=20)  # repaired
    _feed(monitors[3], 30, lambda d: 0.0, seed=4)
    _feed(monitors[4], 6, lambda d: 0.0, seed=5)  # still learning
    assert monitors[0].stages.alarm.first_alarm and monitors[2].stages.alarm.closed and not monitors[2].stages.alarm.first_alarm
    statuses = [UnitStatus(m.unit, "monitored" if m.stages.baseline.pca is not None else "learning", "twin", "calibrated",
                           "" if m.stages.baseline.pca is not None else f"learning: {len(m.stages.baseline.training)} of 10 logs", len(m.rows) or
                           len(m.stages.baseline.training),
                           m.rows[-1].stamp if m.rows else m.stages.baseline.training[-1][0]) for m in monitors]
    statuses.append(UnitStatus(UNITS[5], "not monitored", "twin", "", "no log", 0, ""))
    return [report.alarms_table(monitors), report.scores_table(monitors, N_AXES), report.units_table(statuses)], monitors


def make_output(out: Path) -> Path:
    """A monitor output folder (units.csv, alarms.csv, scores.csv) of :data:`UNITS`."""
    out.mkdir(parents=True, exist_ok=True)
    for table in make_tables()[0]:
        table.write(out)
    return out


def _csv(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return [{k: tables.unescaped(v) for k, v in row.items()} for row in csv.DictReader(f)]


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    out = make_output(tmp_path_factory.mktemp("report") / "OUT")
    page.write(out, SETTINGS, robot="irb6700", logs="/data/LOGS", model="per-unit", twin_temperature=False)
    return out


@pytest.fixture(scope="module")
def browser():
    """Headless Chromium with its console and network logs; a missing browser fails the test, with
    what to install (the README's set-up and `.ci/run` install it): never a skip."""
    if not (CHROMIUM.is_file() and CHROMEDRIVER.is_file()):
        pytest.fail(f"{CHROMIUM} or {CHROMEDRIVER} missing: apt-get install chromium chromium-driver (the README's "
                    "set-up; .ci/run does)")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = Path(os.environ.get("TMPDIR", "/tmp")) / f"faultgen-chromium-{os.getpid()}"
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--disable-dev-shm-usage", "--window-size=1200,800", f"--user-data-dir={profile}"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=str(CHROMEDRIVER)), options=options)
    try:
        driver.set_window_size(1200, 800)
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def test_the_page_in_a_real_browser(written, browser, tmp_path):
    import json

    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    url = (written / page.PAGE).resolve().as_uri()
    browser.get_log("performance")  # what the browser did before: its own new-tab page
    browser.get(url)
    WebDriverWait(browser, 20).until(lambda d: d.execute_script("return window.Plotly !== undefined"))
    browser.save_screenshot(str(tmp_path / "report-page.png"))
    if os.environ.get("FAULTGEN_SCREENSHOT"):
        shutil.copy(tmp_path / "report-page.png", ROOT / "docs" / "report-page.png")

    # the fleet table holds units.csv's and alarms.csv's rows, the open alarm first; since issue 75 (item 6)
    # a line per unit (state light, service by, axis, wear, life consumed, last log): the status, the alarm's
    # start, the logs scored and the closed alarms are in the unit's panel (faultgen.monitor.lights)
    units = {r["unit"]: r for r in _csv(written / "units.csv")}
    alarms = _csv(written / "alarms.csv")
    current = {r["unit"]: r for r in alarms if not r["closed"]}
    closed = {u: [r for r in alarms if r["unit"] == u and r["closed"]] for u in units}
    header = [th.text for th in browser.find_elements(By.CSS_SELECTOR, "#fleet thead th")]
    rows = [dict(zip(header, (td.text for td in tr.find_elements(By.TAG_NAME, "td"))))
            for tr in browser.find_elements(By.CSS_SELECTOR, "#fleet tbody tr")]
    assert sorted(r["unit"] for r in rows) == sorted(units) and len(rows) == len(units)
    assert rows[0]["unit"] == "weld-07" and rows[0]["state"] == "watch"
    # =new-cell's last log is 24 days before the fleet's latest: stale, before the unknown spare-01
    assert [r["unit"] for r in rows] == ["weld-07", "=new-cell", "spare-01", "weld-02", "paint-11", HOSTILE]
    assert [r["state"] for r in rows] == ["watch", "stale", "unknown", "ok", "ok", "ok"]
    fleet = {u.name: u for u in page.read(written).units}
    for row in rows:
        unit, alarm = units[row["unit"]], current.get(row["unit"])
        assert row["last log"] == unit["last_log"]
        wear = fleet[row["unit"]].axis_wear()
        assert row["axis"] == (alarm["source_axis"] if alarm and alarm["first_alarm"] else str(wear[0]) if wear else "")
        link = next(a for a in browser.find_elements(By.CSS_SELECTOR, "a.unit-link") if a.text == row["unit"])
        panel = browser.find_element(By.ID, link.get_attribute("href").split("#")[1]).get_attribute("textContent")
        assert f"{unit['status']} (" in panel and f"{unit['logs_scored']} logs scored" in panel
        opened = bool(alarm and alarm["first_alarm"])
        assert ("Open alarm from" in panel) == opened and (not opened or f"from {alarm['first_alarm']}" in panel)
        assert panel.count(", closed ") == len(closed[row["unit"]])
        if row["unit"] == "paint-11":
            assert "closed 2026-03-21 06:00 by repair of axis 2" in panel
    assert current["weld-07"]["source_axis"] == "2" and rows[0]["wear, % (90 %)"].endswith(")")
    # the stranger's unit name is text, not markup; nothing on the page points outside it
    assert browser.execute_script("return document.images.length") == 0
    links = browser.execute_script(
        "return Array.from(document.querySelectorAll('[src],[href]')).map(e => e.getAttribute('src') || "
        "e.getAttribute('href'))")
    assert all(link.startswith("#") for link in links), links
    assert "Chance of a persistent alarm on a healthy unit" in browser.find_element(By.ID, "statement").text

    # clicking a unit opens its panel and draws its chart
    panels = browser.find_elements(By.CSS_SELECTOR, "details.unit")
    assert len(panels) == len(units) and not any(p.get_attribute("open") for p in panels)
    for name in ("weld-07", HOSTILE):
        link = next(a for a in browser.find_elements(By.CSS_SELECTOR, "a.unit-link") if a.text == name)
        link.click()
        target = browser.find_element(By.ID, link.get_attribute("href").split("#")[1])
        WebDriverWait(browser, 20).until(lambda d, t=target: t.find_elements(By.CSS_SELECTOR, ".chart svg.main-svg"))
        assert target.get_attribute("open") is not None
        svg = target.find_element(By.CSS_SELECTOR, ".chart svg.main-svg")
        assert svg.is_displayed() and svg.size["width"] > 300 and svg.size["height"] > 200
        assert len(target.find_elements(By.CSS_SELECTOR, ".chart .scatterlayer .trace")) >= 2 * N_AXES + 3
        assert target.find_element(By.TAG_NAME, "summary").text.startswith(name)
    if os.environ.get("FAULTGEN_SCREENSHOT"):  # the worn unit's panel, scrolled to
        browser.execute_script("document.getElementById(arguments[0]).scrollIntoView()", "unit-0")
        browser.save_screenshot(str(ROOT / "docs" / "report-unit.png"))
    worn = browser.find_element(By.CSS_SELECTOR, "details.unit[open]")
    assert "wear estimate" in worn.find_element(By.CSS_SELECTOR, ".evidence").text
    browser.find_element(By.ID, "open-all").click()
    scored = {r["unit"] for r in _csv(written / "scores.csv")}  # a unit still learning has no row yet
    assert len(scored) == 4
    WebDriverWait(browser, 20).until(lambda d: len(d.find_elements(By.CSS_SELECTOR, ".chart.js-plotly-plot")) == len(scored))
    assert browser.execute_script("return document.images.length") == 0

    # no console error, no request but the page itself
    console = browser.get_log("browser")
    assert not [e for e in console if e["level"] in ("SEVERE", "WARNING")], console
    events = [json.loads(e["message"])["message"] for e in browser.get_log("performance")]
    requests = [m["params"] for m in events if m["method"] == "Network.requestWillBeSent"]
    assert {r["request"]["url"] for r in requests if r.get("documentURL") == url} == {url}, requests
    assert not [r for r in requests if r["request"]["url"].split(":")[0] in ("http", "https", "ws", "wss")], requests


def test_report_builds_the_page_again_from_an_output_folder(written, tmp_path):
    out = shutil.copytree(written, tmp_path / "OUT")
    (out / page.PAGE).unlink()
    result = CliRunner().invoke(app, ["report", str(out)])
    assert result.exit_code == 0, result.output
    assert (out / page.PAGE).read_bytes() == (written / page.PAGE).read_bytes()
    assert str(out / page.PAGE) in result.output
    text = (out / page.PAGE).read_text()
    assert HOSTILE not in text and "press&lt;img src=x onerror=alert(1)&gt;" in text
    assert text.count("plotly.js v") == 1 and "<script src" not in text and "<link" not in text
    (out / page.SETTINGS).unlink()  # a folder without the settings: the page without them, said so
    result = CliRunner().invoke(app, ["report", str(out)])
    assert result.exit_code == 0 and "settings were not found" in (out / page.PAGE).read_text()
    missing = CliRunner().invoke(app, ["report", str(tmp_path / "nothing")])
    assert missing.exit_code == 2 and "units.csv" in missing.output
    # this folder has no rul.csv and no life.csv: each named, not dropped silently
    assert f"note: {out / 'rul.csv'} is missing: the page shows no remaining life" in result.output
    assert f"note: {out / 'life.csv'} is missing: the page shows no life consumed by load" in result.output


def test_the_page_from_the_tables_in_memory_is_the_page_from_the_files(written, tmp_path):
    """page.write given the fleet of the tables a run holds (record.Table.records; its typed rows,
    record.LogRow, at the tables' digits) draws the page that `faultgen report` draws from the files,
    byte for byte, reading none: here the twin's wear, alarms, maintenance, and unit names a
    spreadsheet would take for a formula (written escaped, read back unescaped) or HTML."""
    made, monitors = make_tables()
    rows = [r.tabled() for m in monitors for r in m.rows]
    assert rows and all(r.wear is not None for r in rows)
    fleet = page.fleet_of({t.name: t.records() for t in made}, rows)
    assert [u.name for u in fleet.units] == [u.name for u in page.read(written).units] and "=new-cell" in UNITS
    out = tmp_path / "OUT"
    out.mkdir()
    page.write(out, SETTINGS, fleet=fleet, robot="irb6700", logs="/data/LOGS", model="per-unit", twin_temperature=False)
    assert sorted(p.name for p in out.iterdir()) == [page.PAGE, page.SETTINGS]
    assert (out / page.PAGE).read_bytes() == (written / page.PAGE).read_bytes()


def test_every_chart_is_a_valid_plotly_figure_with_escaped_text(written):
    import plotly.graph_objects as go

    fleet = page.read(written)
    assert [u.name for u in fleet.units][:1] == ["weld-07"] and fleet.n_axes == N_AXES and fleet.twin
    settings = run_settings.read_settings(written)
    assert settings["wear_limit"] == 5.0 and settings["robot"] == "irb6700"
    for unit in fleet.units:
        if unit.scores:
            figure = page.figure(unit, settings)
            go.Figure(figure)  # every property one plotly knows
            texts = [a["text"] for a in figure["layout"]["annotations"]]
            assert all("<" not in t.replace("<br>", "") for t in texts)  # plotly's line break only
    repaired = next(u for u in fleet.units if u.name == "paint-11")
    texts = [a["text"] for a in page.figure(repaired, settings)["layout"]["annotations"]]
    assert "maintenance: offset learned again" in texts and any("closed by repair of axis 2" in t for t in texts)


def test_monitor_writes_the_page(tmp_path, monkeypatch):
    """The monitor itself writes report.html and settings.json with its outputs (protocol own, a
    small synthetic fleet: `faultgen monitor ... --no-progress`), from the tables it holds: it opens
    none of its output tables for reading (issue 84 item 4), and `faultgen report` draws the same page
    from the files."""
    sys.path.insert(0, str(Path(__file__).parent))
    import fleetlog_folder

    from faultgen.model import robots

    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", robots.load("puma560"), units=2, days=12)
    out = tmp_path / "OUT"
    outputs = {"units.csv", "alarms.csv", "scores.csv", "wear.csv", "rul.csv", "life.csv", "tests.csv"}
    read_back = []

    def watched(real):
        def open_(file, mode="r", *args, **kwargs):
            if Path(str(file)).name in outputs and not any(c in mode for c in "wax+"):
                read_back.append(str(file))
            return real(file, mode, *args, **kwargs)
        return open_

    def refused(folder, name, *args, **kwargs):
        read_back.append(f"tables.read {name}")
        raise AssertionError(f"the run read back {name}")

    with monkeypatch.context() as patched:
        import builtins
        import io

        patched.setattr(builtins, "open", watched(builtins.open))
        patched.setattr(io, "open", watched(io.open))
        patched.setattr(tables, "read", refused)
        result = CliRunner().invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out), "--protocol",
                                          "own", "--train", "10", "--no-progress"])
    assert result.exit_code == 0, result.output
    assert read_back == [] and outputs - {"tests.csv"} <= {p.name for p in out.iterdir()}
    assert str(out / page.PAGE) in result.output
    assert run_settings.read_settings(out)["protocol"] == "own"
    for name in (page.PAGE, page.SETTINGS):  # LOGS by its name: a page meant to be shared holds no path of ours
        assert str(tmp_path) not in (out / name).read_text(), name
    statement = next(line for line in result.output.splitlines() if "Chance of a persistent alarm" in line)
    assert html.escape(statement) in (out / page.PAGE).read_text()
    again = shutil.copytree(out, tmp_path / "again")  # the run's page (its rows in memory) is the one read back
    (again / page.PAGE).unlink()
    assert CliRunner().invoke(app, ["report", str(again)]).exit_code == 0
    assert (again / page.PAGE).read_bytes() == (out / page.PAGE).read_bytes()


def test_the_remaining_life_is_in_the_table_and_the_units_panel(written, tmp_path):
    """With rul.csv (issue 59) the table gives the shown axis's remaining life and its interval, or
    the verdict when there is no end of life; each unit's panel lists every axis's."""
    out = tmp_path / "OUT"
    shutil.copytree(written, out)
    fleet = page.read(out)
    alarmed = next(u for u in fleet.units if u.open_alarm)
    axis = int(alarmed.current["source_axis"])
    quiet = next(u for u in fleet.units if not u.open_alarm and u.axis_wear() is not None)
    rows = [{"unit": alarmed.name, "axis": axis, "rul": 12.4, "rul_5": 8.1, "rul_95": 20.2, "time_unit": "days",
             "model": "linear", "logs_fitted": 9, "verdict": "end of life in 12 days"},
            {"unit": quiet.name, "axis": quiet.axis_wear()[0], "rul": "", "rul_5": "", "rul_95": "", "time_unit": "days",
             "model": "", "logs_fitted": "", "verdict": "no end of life within the horizon (365 days)"}]
    with open(out / "rul.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    text = page.write(out, SETTINGS).read_text()
    assert "Remaining life (5-95 %)" in text  # in the panel since issue 75 (item 6): the table has "service by"
    assert "12 days (8-20)" in text and "(linear trend of 9 logs)" in text
    assert "no end of life within the horizon (365 days)" in text
