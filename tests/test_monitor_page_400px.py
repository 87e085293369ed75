"""A unit's charts read at 400 px in a real browser (issue 88, item 6): each y-axis title of the
unit chart stays beside its own panel (one line of the longest ran past it into the other's), an
alarm's label stays inside the chart (an alarm in the middle of the logs, known two days after it
started, ran off the right edge), and plotly's toolbar leaves the friction curve's title free.
The OUT folder is written by hand (tests/test_monitor_page_lights.py's ``make_out``); Debian's headless
Chromium (tests/test_report_page.py's fixture)."""

from __future__ import annotations

import csv

from test_monitor_page_lights import Spec, day, make_out
from test_report_page import browser  # noqa: F401  (the headless Chromium fixture)

from faultgen.monitor import page

SETTINGS = {"protocol": "twin", "alpha": 0.01, "persistence": 3, "train": 10, "wear_limit": 5.0}
SPECS = (Spec("watch-alarm", alarm=3, wear=(1.0, 2.0, 12.0), scale="friction test", logs=30),
         Spec("mid-alarm", alarm=2, logs=6, wear=(1.0, 30.0, 0.5)))

#: Per chart of a unit's panel: the svg's box, its y-axis titles' and their panels' (the subplots'
#: drag areas), the annotations', the title's and the toolbar's ([left, top, right, bottom], px).
BOXES = """
function box(e){if(!e)return null;var r=e.getBoundingClientRect();return [r.left,r.top,r.right,r.bottom];}
return Array.from(arguments[0].querySelectorAll('.chart')).map(function(c){
  return {svg: box(c.querySelector('svg.main-svg')), ytitle: box(c.querySelector('.g-ytitle')),
          y2title: box(c.querySelector('.g-y2title')), xy: box(c.querySelector('.draglayer .xy .nsewdrag')),
          xy2: box(c.querySelector('.draglayer .xy2 .nsewdrag')),
          notes: Array.from(c.querySelectorAll('.annotation')).map(function(a){return [a.textContent, box(a)];}),
          title: box(c.querySelector('.gtitle')), modebar: box(c.querySelector('.modebar'))};});
"""


def _apart(a, b) -> bool:
    return a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]


def test_a_units_charts_read_at_400_px(tmp_path, browser):  # noqa: F811
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    out = make_out(tmp_path / "OUT", SPECS)
    with open(out / "alarms.csv", newline="") as f:
        rows = list(csv.reader(f))
    for row in rows[1:]:
        if row[0] == "mid-alarm":
            row[2] = day(29)  # known two days after the log it started from
    with open(out / "alarms.csv", "w", newline="") as f:
        csv.writer(f).writerows(rows)
    page.write(out, SETTINGS)
    browser.set_window_size(400, 800)
    try:
        browser.get((out / page.PAGE).resolve().as_uri())
        WebDriverWait(browser, 20).until(lambda d: d.execute_script("return window.Plotly !== undefined"))
        for name, charts in (("mid-alarm", 1), ("watch-alarm", 2)):
            link = next(a for a in browser.find_elements(By.CSS_SELECTOR, "a.unit-link") if a.text == name)
            link.click()
            panel = browser.find_element(By.ID, link.get_attribute("href").split("#")[1])
            WebDriverWait(browser, 20).until(
                lambda d: len(panel.find_elements(By.CSS_SELECTOR, ".chart svg.main-svg")) >= 3 * charts)
            found = browser.execute_script(BOXES, panel)
            chart = found[0]
            assert chart["svg"][2] <= 400, chart
            # each y title beside its own panel, apart from the other's
            for title, area in (("ytitle", "xy"), ("y2title", "xy2")):
                assert chart[area][1] - 1 <= chart[title][1] and chart[title][3] <= chart[area][3] + 1, (name, title, chart)
            assert _apart(chart["ytitle"], chart["y2title"]), chart
            alarms = [box for text, box in chart["notes"] if text.startswith("alarm")]
            assert alarms, chart["notes"]
            for text, box in chart["notes"]:  # every label inside the chart
                assert chart["svg"][0] <= box[0] and box[2] <= chart["svg"][2], (name, text, box, chart["svg"])
            if charts == 2:  # the friction curve: its title clear of plotly's toolbar
                curve = found[1]
                assert curve["title"] and curve["modebar"] and _apart(curve["title"], curve["modebar"]), curve
        console = browser.get_log("browser")
        assert not [e for e in console if e["level"] in ("SEVERE", "WARNING")], console
    finally:
        browser.set_window_size(1200, 800)
