"""The diagnosis report (issue 10, item 6): figures and one self-contained page, for a fit and a non-fit."""

from __future__ import annotations

import base64
import os
import re
import shutil
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

import emaphm
from emaphm.report import REPORT_FILES, write_report
from emaphm.results import SimResult
from tests.helpers import run_cli

ROOT = Path(__file__).resolve().parents[1]
BUDGET = {"pop_size": 16, "generations": 3, "polish": False}
# enough search for the Table 1 faults to come out present (16 x 3 may leave every one "cannot tell")
FITTED = {"pop_size": 16, "generations": 10, "polish": False}


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.images: list[str] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):  # type: ignore[no-untyped-def]
        if tag == "img":
            self.images.append(dict(attrs)["src"])

    def handle_data(self, data):  # type: ignore[no-untyped-def]
        self.text.append(data)


def _read(page: Path) -> _Page:
    parsed = _Page()
    parsed.feed(page.read_text(encoding="utf-8"))
    return parsed


@pytest.fixture(scope="module")
def measured():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=5)


def test_a_report_shows_the_verdict_faults_and_figures_and_needs_nothing_else(measured, tmp_path):
    result = emaphm.identify(reference=measured, seed=1, **FITTED)
    page = write_report(result, tmp_path / "rep", provenance={"reference": "twin.h5", "sha256": "ab12"})
    assert sorted(p.name for p in (tmp_path / "rep").iterdir()) == sorted(REPORT_FILES)
    parsed = _read(page)
    text = " ".join(parsed.text)
    # a 16 x 10 search without polish may fit less well than the twin's usual: then doubtful, with its reasons
    assert result.verdict in ("fits", "doubtful") and f"{result.verdict}: detected" in text and "does not fit" not in text
    assert all(d in text for d in result.doubts)
    for i, name in enumerate(emaphm.FAULT_NAMES, start=1):
        assert f"k{i} {name}" in text
    assert '<td class="present">' in page.read_text()
    assert f"{result.estimate[0]:.4f}" in text and "ab12" in text and result.settings["reference"] in text
    # three figures, each a PNG inside the page (self-contained: no file or address outside it)
    assert len(parsed.images) == 3
    for src in parsed.images:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    assert not re.search(r'(?:src|href)="(?!data:)', page.read_text())
    # the warnings and the input's conversion are shown
    import dataclasses

    warned = dataclasses.replace(result, warnings=["the offset looks 180 deg off"])
    page = write_report(
        warned, tmp_path / "rep2", provenance={"channel_map": "rig.toml", "conversion": {"θ0": 71.3}}
    )
    text = " ".join(_read(page).text)
    assert (
        "Warnings" in text
        and "the offset looks 180 deg off" in text
        and "rig.toml" in text
        and "71.3" in text
    )
    # the fit's caption names the model whose current it shows: the LF model without a last stage,
    # the switching model after one (`FaultIdentifier.curves`)
    assert "the LF model at the identified faults" in text
    staged = dataclasses.replace(result, settings={**result.settings, "stages": [{"stage": "last_stage", "switching": {"taken": True}}]})
    text = " ".join(_read(write_report(staged, tmp_path / "rep3")).text)
    assert "the switching model at the identified faults" in text and "LF model at" not in text


def test_a_recording_the_model_cannot_explain_reports_no_fault(measured, tmp_path):
    wrong = SimResult(t=measured.t, signals={**measured.signals, "i_q": -measured.i_q})  # sign flipped
    result = emaphm.identify(reference=wrong, seed=1, **BUDGET)
    assert result.verdict == "does not fit"
    page = write_report(result, tmp_path / "rep")
    text = " ".join(_read(page).text)
    assert "does not fit" in text and "no faults are reported" in text
    assert '<td class="present">' not in page.read_text()  # no fault marked present


def test_input_provenance_names_the_file_and_its_hash_or_the_twin(tmp_path):
    import json

    import numpy as np

    from emaphm.report import input_provenance

    twin = input_provenance(None, truth=np.array([0.3, 0, 0, 0, 0, 0, 0, 0.5]))
    assert twin == {"reference": "HF twin, noise on", "sha256": None, "true_faults": [0.3, 0, 0, 0, 0, 0, 0, 0.5],
                    "channel_map": None, "conversion": None, "params": "nominal", "calibration": "packaged"}  # fmt: skip
    (tmp_path / "rec.csv").write_text("t,i_a\n")
    rig = input_provenance(tmp_path / "rec.csv", channel_map=tmp_path / "rig.toml", conversion={"f_s": 1e4},
                           params=tmp_path / "a.toml", calibration=tmp_path / "c.json")  # fmt: skip
    assert rig["sha256"] == emaphm.io.sha256_of(tmp_path / "rec.csv") and rig["true_faults"] is None
    assert rig["channel_map"] == str(tmp_path / "rig.toml") and rig["conversion"] == {"f_s": 1e4}
    assert (rig["params"], rig["calibration"]) == (str(tmp_path / "a.toml"), str(tmp_path / "c.json"))
    json.dumps(rig)  # JSON-ready, as write_report shows it


def test_cli_report_and_a_bad_report_path(measured, tmp_path, capsys):
    path = tmp_path / "ref.h5"
    emaphm.write_trace(measured, path)
    args = ["identify", "--reference", str(path), "--pop-size", "16", "--generations", "3", "--no-polish"]
    code, _, err = run_cli([*args, "--report", str(tmp_path / "rep")], capsys)
    assert code in (0, 4) and (tmp_path / "rep" / "index.html").is_file() and "wrote the report" in err
    assert emaphm.io.sha256_of(path) in (tmp_path / "rep" / "index.html").read_text()
    (tmp_path / "afile").write_text("x")
    code, out, err = run_cli([*args, "--report", str(tmp_path / "afile")], capsys)
    assert code == 2 and out == "" and "not a folder" in err and err.count("\n") == 1


@pytest.mark.skipif(
    shutil.which("chromium") is None and not os.environ.get("EMAPHM_REQUIRE_BROWSER"),
    reason="no headless Chromium (apt install chromium); .ci/run installs it and requires this test",
)
def test_the_report_renders_in_a_real_headless_browser(measured, tmp_path):
    assert shutil.which("chromium"), "EMAPHM_REQUIRE_BROWSER is set but chromium is not installed"
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        from check_report_in_browser import check
    finally:
        sys.path.pop(0)
    result = emaphm.identify(reference=measured, seed=1, **BUDGET)
    write_report(result, tmp_path / "rep")
    assert check(tmp_path / "rep") == []
