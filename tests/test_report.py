"""The diagnosis report (issue 10, item 6; issue 34, item 4): figures and one self-contained page a
planner reads, for a fit, a doubtful fit and a non-fit."""

from __future__ import annotations

import base64
import dataclasses
import json
import os
import re
import shutil
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import emaphm
from emaphm.identification.result import IdentificationResult
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
        self.alts: list[str] = []
        self.links: dict[str, str] = {}
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):  # type: ignore[no-untyped-def]
        if tag == "img":
            self.images.append(dict(attrs)["src"])
            self.alts.append(dict(attrs)["alt"])
        if tag == "a":
            self.links[dict(attrs).get("id", "")] = dict(attrs)["href"]

    def handle_data(self, data):  # type: ignore[no-untyped-def]
        self.text.append(data)


def _read(page: Path) -> _Page:
    parsed = _Page()
    parsed.feed(page.read_text(encoding="utf-8"))
    return parsed


@pytest.fixture(scope="module")
def measured():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=5)


def _constructed(estimate, *, fit_nrmse=0.02, **changes):  # type: ignore[no-untyped-def]
    """An `IdentificationResult` made by hand (no search): `fit_nrmse` 0.02 fits, above 0.5 does not."""
    k = np.array(estimate, dtype=float)
    detected = list(emaphm.detect(k)) if fit_nrmse <= 0.5 else []
    fields = dict(estimate=k, fitness=0.01, evaluations=48, wall_time_s=0.5, seed=1, optimizer="ga",
                  detected=detected, history=[0.1, 0.02, 0.01],
                  settings={"reference": "rig.h5", "params": {"source": "nominal", "params_hash": None}},
                  fit_nrmse=fit_nrmse)  # fmt: skip
    return IdentificationResult(**{**fields, **changes})


def _visible(page: Path) -> str:
    return " ".join(_read(page).text)


def test_a_report_shows_the_verdict_faults_and_figures_and_needs_nothing_else(measured, tmp_path):
    result = emaphm.identify(reference=measured, seed=1, actuator_id="A-007", **FITTED)
    page = write_report(result, tmp_path / "rep", provenance={"reference": "twin.h5", "sha256": "ab12"})
    assert sorted(p.name for p in (tmp_path / "rep").iterdir()) == sorted(REPORT_FILES)
    source = page.read_text()
    text = _visible(page)
    # a 16 x 10 search without polish may fit less well than the twin's usual: then doubtful, with its reasons
    assert result.verdict in ("fits", "doubtful") and "does not fit" not in text
    # the verdict first and big: its block comes before any table, its word alone in the block's heading
    word = {"fits": "fits", "doubtful": "doubtful"}[result.verdict]
    assert re.search(rf'<div class="verdict (fits|doubt)"><p class="word">{word}</p>', source)
    assert source.index('class="verdict') < source.index("<table")
    for name in result.detected:
        assert name in source[source.index('class="verdict') : source.index("</div>")]
    # the faults in physical units and the fault vector; detected faults marked present
    for i, name in enumerate(emaphm.FAULT_NAMES, start=1):
        assert f"k{i} {name}" in text
    assert '<td class="present">' in source and "N·m" in text and "mrad" in text and "% of K_P0" in text
    assert f"{result.estimate[0]:.4f}" in text and "ab12" in text and "twin.h5" in text
    # the actuator's id (recorded in the result) and the baseline
    assert result.settings["actuator_id"] == "A-007" and "A-007" in text
    assert "baseline none (the actuator file's nameplate)" in text
    # three figures, each a PNG inside the page (self-contained: no file or address outside it)
    parsed = _read(page)
    assert len(parsed.images) == 3
    for src in parsed.images:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    assert not re.search(r'(?:src|href)="(?!data:)', source)
    # the JSON is a download (decoding to the result's JSON), not printed on the page
    assert json.loads(base64.b64decode(parsed.links["result-json"].split(",", 1)[1])) == json.loads(
        json.dumps(result.to_json(), default=str)
    )
    assert "<pre" not in source and '"estimate"' not in text
    # the warnings and the input's conversion are shown
    warned = dataclasses.replace(result, warnings=["the offset looks 180 deg off"])
    page = write_report(
        warned, tmp_path / "rep2", provenance={"channel_map": "rig.toml", "conversion": {"θ0": 71.3}}
    )
    text = _visible(page)
    assert (
        "Warnings" in text
        and "the offset looks 180 deg off" in text
        and "rig.toml" in text
        and "71.3" in text
    )
    # the fit's caption names the model whose current it shows: the LF model without a last stage,
    # the switching model after one (`FaultIdentifier.curves`)
    assert "the LF model at the identified faults" in text
    staged = dataclasses.replace(
        result,
        settings={**result.settings, "stages": [{"stage": "last_stage", "switching": {"taken": True}}]},
    )
    text = _visible(write_report(staged, tmp_path / "rep3"))
    assert "the switching model at the identified faults" in text and "LF model at" not in text


def test_a_doubtful_report_lists_its_reasons_right_under_the_verdict(tmp_path):
    reasons = ["the recording starts in motion", "a command the monitor was not calibrated on"]
    result = _constructed(
        [0.3, 0, 0, 0, 0, 0, 0, 0.5], doubts=reasons, warnings=[*reasons, "an unrelated note"]
    )
    assert result.verdict == "doubtful"
    source = write_report(result, tmp_path / "rep").read_text()
    block = source[source.index('<div class="verdict doubt">') : source.index("</div>")]
    assert '<p class="word">doubtful</p>' in block and "friction" in block
    assert all(f"<li>{r}</li>" in block for r in reasons) and "unrelated" not in block
    assert source.count("the recording starts in motion") == 1  # not repeated among the warnings
    assert "an unrelated note" in source[source.index("</div>") :]


def test_a_recording_the_model_cannot_explain_reports_no_fault(measured, tmp_path):
    wrong = SimResult(t=measured.t, signals={**measured.signals, "i_q": -measured.i_q})  # sign flipped
    result = emaphm.identify(reference=wrong, seed=1, **BUDGET)
    assert result.verdict == "does not fit"
    # a fitting report first in the same folder: its faults figure must not survive the non-fit's
    write_report(_constructed([0.3, 0, 0, 0, 0, 0, 0, 0.5]), tmp_path / "rep")
    assert (tmp_path / "rep" / "faults.png").is_file()
    page = write_report(result, tmp_path / "rep")
    source, text = page.read_text(), _visible(page)
    assert re.search(r'<div class="verdict nofit"><p class="word">does not fit</p>', source)
    assert "no faults are reported" in text and "No faults are reported" in text
    # no fault values tabled, no fault bars drawn: the search's end point is in the JSON only
    assert '<td class="present">' not in source and '<table class="physical"' not in source
    assert "k1 friction" not in text and "k8 kp_drift" not in text
    assert all(f"{v:.4f}" not in text for v in result.estimate)
    assert not (tmp_path / "rep" / "faults.png").exists()
    assert [a for a in _read(page).alts if "faults" in a.lower()] == []
    assert len(_read(page).images) == 2  # the fit and the convergence


def test_the_faults_are_given_in_the_actuators_physical_units(tmp_path):
    from emaphm.tables import physical_faults

    k = [0.25, 0.04, 0.1, 0, 0.3, 0.2, 0.25, 0.46]
    nominal = emaphm.EmaParams()
    tr = nominal.transmission
    v = physical_faults(k, nominal)
    # friction k1 = 0.25: F_S = F_S0·(1 + 2·0.25) = 1.5 × nominal (N·m); backlash B0·(1 + 99·k2) in mrad
    assert v["friction"]["times_nominal"] == pytest.approx(1.5, rel=1e-12)
    assert v["friction"]["F_S"] == pytest.approx(1.5 * tr.F_S0, rel=1e-12)
    assert v["backlash"]["B_mrad"] == pytest.approx(1e3 * tr.B0 * (1 + 99 * 0.04), rel=1e-12)
    # shorts in % of the phase's turns, eccentricity in %, its direction in electrical degrees
    assert v["short_a"]["shorted_percent"] == pytest.approx(10.0) and v["short_b"]["shorted_percent"] == 0.0
    assert v["eccentricity"]["zeta_percent"] == pytest.approx(20.0)
    assert v["eccentricity"]["phi_e_deg"] == pytest.approx(90.0)
    # k8 = 0.46: K_P = K_P0·(0.5 + 0.46), a drift of -4 % of K_P0
    assert v["kp_drift"]["drift_percent"] == pytest.approx(-4.0, abs=1e-9)
    assert v["kp_drift"]["K_P"] == pytest.approx(0.96 * nominal.controller.K_P0, rel=1e-12)
    # another actuator: its own nominal values, and the page says them
    other = dataclasses.replace(
        nominal,
        transmission=dataclasses.replace(tr, F_S0=0.08, F_D0=0.05, B0=1e-3),
        controller=dataclasses.replace(nominal.controller, K_P0=100.0),
    )
    v = physical_faults(k, other)
    assert v["friction"]["F_S"] == pytest.approx(0.12) and v["backlash"]["B_mrad"] == pytest.approx(4.96)
    assert v["kp_drift"]["K_P"] == pytest.approx(96.0)
    text = _visible(write_report(_constructed(k), tmp_path / "rep", params=other))
    for shown in ("F_S 0.12 N·m (1.50 × nominal)", "B 4.96 mrad (5.0 × nominal)", "10.0 % of phase A's turns",
                  "ζ 20.0 %", "direction 90° electrical", "K_P 96 A/rad (-4.0 % of K_P0)"):  # fmt: skip
        assert shown in text, shown
    # the CLI's fault table is unchanged
    from emaphm.tables import fault_rows

    columns, rows = fault_rows(_constructed(k).to_json())
    assert columns == ["fault", "identified", "verdict"] and rows[0][:2] == ["k1 friction", "0.2500"]


def test_the_faults_figure_draws_distances_from_healthy_and_the_thresholds(tmp_path, monkeypatch):
    import emaphm.plots
    from emaphm.identification.detection import load_thresholds

    calls = []
    original = emaphm.plots.plot_faults
    monkeypatch.setattr(
        emaphm.plots, "plot_faults", lambda *a, **kw: calls.append((a, kw)) or original(*a, **kw)
    )
    k = [0.25, 0.04, 0.1, 0, 0.3, 0.2, 0.7, 0.46]
    failure = {"friction": 0.45, "kp_drift": 0.03}
    page = write_report(_constructed(k), tmp_path / "rep", failure_thresholds=failure)
    (distance, path), kw = calls[0]
    # k7 (a direction) is not a bar; k8 is drawn as its signed distance from its healthy 0.5
    assert list(distance) == [n for n in emaphm.FAULT_NAMES if n != "eccentricity_phase"]
    assert distance["kp_drift"] == pytest.approx(-0.04) and distance["friction"] == pytest.approx(0.25)
    assert "252° electrical" in kw["note"] and kw["signed"] == ("kp_drift",)
    packaged = dict(load_thresholds()["thresholds"])
    assert kw["thresholds"] == {"detection threshold": packaged, "failure threshold": failure}
    assert path.name == "faults.png" and kw["title"]
    # the thresholds are tabled too: the packaged detection thresholds, the failure ones, one exceeded
    source, text = page.read_text(), _visible(page)
    assert f"{packaged['friction']:.4g}" in text and "0.45" in text and "0.03 (exceeded)" in text
    assert "Detection thresholds: packaged" in text
    # thresholds given (emaphm identify --detection) are the ones shown
    calls.clear()
    given = {name: 0.123 for name in packaged}
    page = write_report(
        _constructed(k), tmp_path / "rep2", thresholds=given, provenance={"detection": "mine.json"}
    )
    assert calls[0][1]["thresholds"] == {"detection threshold": given}
    text = _visible(page)
    assert "0.123" in text and "Detection thresholds: mine.json" in text
    assert "<th>failure threshold</th>" not in page.read_text() and "<th>failure threshold</th>" in source


def test_every_figure_has_a_title_and_units(measured, tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    seen = {}
    original = Figure.savefig

    def spy(fig, path, *args, **kwargs):  # type: ignore[no-untyped-def]
        titles = [fig._suptitle.get_text()] if fig._suptitle is not None else []
        seen[Path(path).name] = (
            titles + [a.get_title() for a in fig.axes],
            [a.get_ylabel() for a in fig.axes],
        )
        return original(fig, path, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", spy)
    write_report(emaphm.identify(reference=measured, seed=1, **BUDGET), tmp_path / "rep")
    assert set(seen) == {"fit.png", "faults.png", "convergence.png"}
    for name, (titles, ylabels) in seen.items():
        assert any(t.strip() for t in titles), name
        assert all(re.search(r"\[.+\]", y) for y in ylabels), (name, ylabels)


def test_the_baseline_is_shown_when_the_result_names_one(tmp_path):
    result = _constructed([0.3, 0, 0, 0, 0, 0, 0, 0.5])
    text = _visible(write_report(result, tmp_path / "rep"))
    assert "baseline none (the actuator file's nameplate)" in text
    assert "actuator not given" in text
    named = dataclasses.replace(result, settings={**result.settings, "baseline": {"path": "A007-new.json"},
                                                  "actuator_id": "A007"})  # fmt: skip
    text = _visible(write_report(named, tmp_path / "rep2"))
    assert (
        "baseline A007-new.json" in text
        and "nameplate" not in text
        and "emaphm diagnosis of actuator A007" in text
    )


def test_input_provenance_names_the_file_and_its_hash_or_the_twin(tmp_path):
    import json

    import numpy as np

    from emaphm.report import input_provenance

    twin = input_provenance(None, truth=np.array([0.3, 0, 0, 0, 0, 0, 0, 0.5]))
    assert twin == {"reference": "HF twin, noise on", "sha256": None, "true_faults": [0.3, 0, 0, 0, 0, 0, 0, 0.5],
                    "channel_map": None, "conversion": None, "params": "nominal", "calibration": "packaged",
                    "detection": "packaged"}  # fmt: skip
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
    # the nominal actuator with failure thresholds: the packaged calibration is its own
    actuator = tmp_path / "actuator.toml"
    actuator.write_text("[thresholds]\nfriction = 0.45\nkp_drift = 0.3\n")
    args = ["identify", "--reference", str(path), "--pop-size", "16", "--generations", "3", "--no-polish"]
    code, out, err = run_cli([*args, "--report", str(tmp_path / "rep"), "--actuator-id", "SN-0042", "--json",
                              "--params", str(actuator)], capsys)  # fmt: skip
    assert code in (0, 3, 4) and (tmp_path / "rep" / "index.html").is_file() and "wrote the report" in err
    data = json.loads(out)
    assert data["settings"]["actuator_id"] == "SN-0042"
    page = tmp_path / "rep" / "index.html"
    text = _visible(page)
    assert emaphm.io.sha256_of(path) in text and "SN-0042" in text and str(actuator) in text
    if data["verdict"] != "does not fit":
        assert "failure threshold" in text and "0.45" in text
    code, out, _ = run_cli([*args, "--json"], capsys)
    assert json.loads(out)["settings"]["actuator_id"] is None
    (tmp_path / "afile").write_text("x")
    code, out, err = run_cli([*args, "--report", str(tmp_path / "afile")], capsys)
    assert code == 2 and out == "" and "not a folder" in err and err.count("\n") == 1
    # a bad [thresholds] table is refused before the work, when a report would show it
    actuator.write_text("[thresholds]\nfriction = 7\n")
    code, out, err = run_cli([*args, "--report", str(tmp_path / "rep4"), "--params", str(actuator)], capsys)
    assert code == 2 and "friction" in err and not (tmp_path / "rep4").exists()


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
    # a page that does not fit: the verdict, no fault values or bars, and the check sees a wrong one
    nofit = _constructed(result.estimate, fit_nrmse=1.5, curves=result.curves)
    write_report(nofit, tmp_path / "nofit")
    assert check(tmp_path / "nofit") == []
    page = tmp_path / "nofit" / "index.html"
    page.write_text(page.read_text().replace("</body>", "<p>k1 friction k8 kp_drift</p></body>"))
    assert check(tmp_path / "nofit") == ["a page that does not fit shows fault values or fault bars"]
