"""Open an emaphm fleet page in a real headless browser and check what a planner would see (issue 35).

    python scripts/check_fleet_in_browser.py FLEET_DIR [--screenshot shot.png]

Loads FLEET_DIR/index.html (written by `emaphm.fleet_page.write_fleet_page`) in headless Chromium
(Debian's `chromium` package; `apt install chromium`), after its script ran, and checks that:
the page's own count of charts parsed as SVG with a title matches the charts in the page and the
first one has a width once shown; the table has one row per actuator (the count the page embeds,
and the entries of FLEET_DIR/fleet.json when it is there); the rows are in urgency order of their
colour (no green before a red) and each shows its colour's name in its chip; the colour chips of the
header count the rows of each colour; every chart is an <svg> with a <title>; an actuator whose
latest diagnosis does not fit shows no worst fault, no threshold share, no fault values and no
chart; a doubtful one is marked as such; the colour code (legend) and the fleet.json and fleet.csv
downloads are there; the page loads nothing from outside itself and links to no web address.
Prints what it found; exit 0 when all hold, 1 otherwise, 2 when no browser is installed.
"""

from __future__ import annotations

import json
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_report_in_browser import rendered_dom, require_browser, run_main, take_screenshot

sys.path.pop(0)

COLOURS = ("red", "orange", "yellow", "green")  # most urgent first
DASH = "—"


class FleetDom(HTMLParser):
    """The parts of a fleet page the checks read: the actuator rows with their cells' text and
    classes, the folded rows under them (charts and fault values inside), the charts' titles, the
    header's chips, and the elements with an ``id``."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.head: list[str] = []  # the #fleet table's column names
        self.rows: list[dict] = []  # {"id", "colour", "verdict", "cells", "classes", "svgs", "values"}
        self.more: dict[str, dict] = {}  # data-for -> {"svgs", "values"}
        self.charts: list[bool] = []  # per <svg>: whether it has a <title>
        self.chips: dict[str, str] = {}  # colour -> data-count (the header's)
        self.ids: dict[str, dict[str, str | None]] = {}  # id -> attributes
        self.sources: list[str] = []  # src attributes (things the page would load)
        self.web_links: list[str] = []
        self._depth = 0  # table nesting inside #fleet (1: its own rows)
        self._row: dict | None = None
        self._cell = False
        self._head = False  # in a column name
        self._svg: list[bool] = []

    def handle_starttag(self, tag, attrs):  # type: ignore[no-untyped-def]
        a = dict(attrs)
        classes = (a.get("class") or "").split()
        if a.get("id"):
            self.ids[a["id"]] = a
        if a.get("src") is not None:
            self.sources.append(a["src"])
        if re.match(r"(?i)(https?:|//)", a.get("href") or ""):
            self.web_links.append(a["href"])
        if tag == "span" and "chip" in classes and a.get("data-count") is not None:
            self.chips[next((c for c in classes if c != "chip"), "")] = a["data-count"]
        if tag == "table" and (self._depth or a.get("id") == "fleet"):
            self._depth += 1
        elif tag == "tr" and self._depth == 1:
            self._start_row(a, classes)
        elif tag in ("td", "th") and self._depth == 1 and self._row is not None and "cells" in self._row:
            self._row["cells"].append("")
            self._row["classes"].append(a.get("class") or "")
            self._cell = True
        elif tag == "th" and self._depth == 1 and self._row is None:
            self.head.append("")
            self._head = True
        elif tag == "svg":
            self._svg.append(False)
            if self._row is not None:
                self._row["svgs"] += 1
        elif tag == "title" and self._svg:
            self._svg[-1] = True
        if "fv" in classes and self._row is not None:
            self._row["values"] += 1

    def _start_row(self, a: dict, classes: list[str]) -> None:
        if "act" in classes:
            self._row = {"id": (a.get("id") or "").removeprefix("a-"), "colour": a.get("data-colour"),
                         "verdict": a.get("data-verdict"), "cells": [], "classes": [], "svgs": 0,
                         "values": 0}  # fmt: skip
            self.rows.append(self._row)
        elif "more" in classes:
            ident = (a.get("data-for") or "").removeprefix("a-")
            self._row = self.more.setdefault(ident, {"svgs": 0, "values": 0})
        else:
            self._row = None

    def handle_endtag(self, tag):  # type: ignore[no-untyped-def]
        if tag == "table" and self._depth:
            self._depth -= 1
        elif tag == "tr" and self._depth == 1:
            self._row = None
        elif tag in ("td", "th") and self._depth == 1:
            self._cell = self._head = False
        elif tag == "svg" and self._svg:
            self.charts.append(self._svg.pop())

    def handle_data(self, data):  # type: ignore[no-untyped-def]
        if self._head:
            self.head[-1] += data
        elif self._cell and self._row is not None and "cells" in self._row:
            self._row["cells"][-1] += data


def page_problems(dom: str, folder: Path | None = None) -> list[str]:
    """The problems found in a fleet page's HTML `dom` (the rendered DOM, or the file itself);
    `folder`: where to find a ``fleet.json`` to count the actuators against."""
    d = FleetDom()
    d.feed(dom)
    d.close()
    table = d.ids.get("fleet")
    if table is None:
        return ["no actuator table (#fleet) in the page"]
    problems = _count_problems(d, table, folder) + _order_problems(d.rows)
    if not all(d.charts):
        problems.append(f"{d.charts.count(False)} of {len(d.charts)} charts have no <title>")
    if table.get("data-charts") != str(len(d.charts)):
        problems.append(f"the page says {table.get('data-charts')} charts, {len(d.charts)} are in it")
    problems += _verdict_problems(d)
    legend = re.search(r'<div id="legend"[^>]*>(.*?)</div>', dom, re.S)
    words = re.sub(r"<[^>]+>", " ", legend.group(1)) if legend else ""
    if legend is None or not all(c in words for c in COLOURS) or "inspection interval" not in words:
        problems.append("no colour code (legend) with the four colours and the inspection interval")
    for name in ("fleet.json", "fleet.csv"):
        if (d.ids.get(f"fleet-{name[6:]}") or {}).get("href") != name:
            problems.append(f"no {name} download link")
    if d.sources or d.web_links:
        problems.append(f"the page loads or links to things outside itself: {(d.sources + d.web_links)[:3]}")
    return problems


def _count_problems(d: FleetDom, table: dict, folder: Path | None) -> list[str]:
    """One row per actuator, and the header's chips counting the rows of each colour."""
    problems = []
    if table.get("data-actuators") != str(len(d.rows)):
        problems.append(f"{len(d.rows)} actuator rows, the page says {table.get('data-actuators')}")
    stored = folder / "fleet.json" if folder is not None else None
    if stored is not None and stored.is_file():
        data = json.loads(stored.read_text(encoding="utf-8"))
        entries = data.get("actuators") if isinstance(data, dict) else data
        if isinstance(entries, list) and len(entries) != len(d.rows):
            problems.append(f"{len(d.rows)} actuator rows, fleet.json has {len(entries)}")
    for colour in COLOURS:
        rows = sum(r["colour"] == colour for r in d.rows)
        if d.chips.get(colour) != str(rows):
            problems.append(f"the header counts {d.chips.get(colour)} {colour}, the table has {rows}")
    return problems


def _order_problems(rows: list[dict]) -> list[str]:
    """Rows in urgency order of their colour, each chip saying its colour's name."""
    problems = []
    for row in rows:
        if row["colour"] not in COLOURS:
            problems.append(f"row {row['id']}: colour {row['colour']!r} is none of {COLOURS}")
        elif not row["cells"] or row["cells"][0].strip() != row["colour"]:
            problems.append(f"row {row['id']}: its chip does not say {row['colour']!r}")
    rank = [COLOURS.index(r["colour"]) if r["colour"] in COLOURS else len(COLOURS) for r in rows]
    for i in range(1, len(rows)):
        if rank[i] < rank[i - 1]:
            problems.append(
                f"rows out of urgency order: {rows[i - 1]['id']} ({rows[i - 1]['colour']}) before "
                f"{rows[i]['id']} ({rows[i]['colour']})"
            )
            break
    return problems


def _verdict_problems(d: FleetDom) -> list[str]:
    """A row that does not fit shows no fault values and no chart; a doubtful one is marked."""
    where = {name: next((i for i, h in enumerate(d.head) if h.startswith(name)), None)
             for name in ("verdict", "worst fault", "threshold share")}  # fmt: skip
    if None in where.values():
        return [f"the table lacks the columns {[k for k, v in where.items() if v is None]}"]
    problems = []
    for row in d.rows:
        cells, classes = row["cells"], row["classes"]
        if len(cells) != len(d.head):
            problems.append(f"row {row['id']}: {len(cells)} cells for {len(d.head)} columns")
            continue
        if cells[where["verdict"]].strip() != row["verdict"]:
            problems.append(f"row {row['id']}: the verdict cell says {cells[where['verdict']]!r}")
        more = d.more.get(row["id"], {"svgs": 0, "values": 0})
        if row["verdict"] == "does not fit":
            shown = [cells[where[k]].strip() for k in ("worst fault", "threshold share")]
            if shown != [DASH, DASH] or row["values"] or more["values"] or row["svgs"] or more["svgs"]:
                problems.append(f"row {row['id']} does not fit but shows fault values or a chart")
        if row["verdict"] == "doubtful" and "doubt" not in classes[where["verdict"]].split():
            problems.append(f"row {row['id']} is doubtful but not marked so")
    return problems


def check(folder: Path, screenshot: Path | None = None) -> list[str]:
    """The problems found in the rendered fleet page ``folder/index.html`` (empty when it is fine)."""
    exe = require_browser()
    page = folder / "index.html"
    dom = rendered_dom(page, exe)
    problems = []
    parsed = re.search(r'data-charts-parsed="(\d+)/(\d+)"', dom)
    width = re.search(r'data-first-chart-width="(\d+)"', dom)
    if parsed is None or width is None:
        problems.append("the page's script did not run (no data-charts-parsed)")
    elif parsed.group(1) != parsed.group(2):
        problems.append(f"charts parsed as SVG with a title: {parsed.group(1)} of {parsed.group(2)}")
    elif parsed.group(2) != "0" and int(width.group(1)) == 0:
        problems.append("the first chart has no width once its details are open")
    problems += page_problems(dom, folder)
    if screenshot is not None:
        take_screenshot(page, exe, screenshot, 1400)
    return problems


def main() -> None:
    run_main(check, "check_fleet_in_browser", "folder", "fleet page")


if __name__ == "__main__":
    main()
