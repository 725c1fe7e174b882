"""The printed form of each command's result (the ``--json`` form is the API's dict as it is).

Tables and lines on stdout (`output.stdout_console`): formatting only, the values come from the
API.
"""

from __future__ import annotations

from typing import Any

from .output import stdout_console

__all__ = [
    "print_identification",
    "print_inspection",
    "print_params",
    "print_rul",
    "print_thresholds",
]


def print_identification(data: dict[str, Any]) -> None:
    """`emaphm identify`'s result: the fault table, the fit, what the extra stages did, the verdict."""
    from ..tables import fault_table

    title = f"identified faults ({data['optimizer']}, seed {data['seed']}"
    title += f", 90 % intervals by {data['uq_method']})" if data["ci90_low"] is not None else ")"
    table = fault_table(data, title)
    verdicts = data.get("fault_verdicts") or {}
    out = stdout_console()
    out.print(table)
    if data["percent_error"] is not None:
        out.print(f"%err {data['percent_error']:.2f}")
    if data["fit_nrmse"] is not None:
        limit = data["settings"].get("doubtful_above") or {}
        usual = (
            f"doubtful above {100 * limit['nrmse']:.2f} % ({limit['source']})"
            if limit
            else "doubtful above 6 %"
        )
        out.print(
            f"fit NRMSE {100 * data['fit_nrmse']:.2f} % of the filtered current ({usual}; above 50 %: does not fit)"
        )
    from ..identification.result import stage_record

    second = stage_record(data["settings"].get("stages", []), "second_search")
    if second is not None and second["ran"]:
        out.print(_second_search_line(second))
    stage = (stage_record(data["settings"].get("stages", []), "last_stage") or {}).get("switching")
    if stage is not None:
        out.print(_switching_stage_line(stage))
    if data["verdict"] == "does not fit":
        out.print("verdict: does not fit (see the warning): no faults reported")
    else:
        if data["verdict"] == "doubtful":
            reasons = len(data.get("doubts") or [])
            out.print(
                f"verdict: doubtful ({reasons} reason{'s' * (reasons != 1)}, in the warnings): the faults below "
                "are what the monitor found, not a sure diagnosis"
            )
        else:
            out.print("verdict: fits")
        out.print(f"detected: {', '.join(data['detected']) or 'none (healthy)'}")
        unsure = [n for n, v in verdicts.items() if v == "cannot tell"]
        if unsure:
            out.print(
                f"cannot tell: {', '.join(unsure)} (the estimate departs from healthy, its interval reaches back)"
            )
    out.print(
        f"fitness {data['fitness']:.4g}, {data['evaluations']} evaluations, {data['wall_time_s']:.1f} s"
    )
    out.print(_inputs_line(data["settings"]), soft_wrap=True)


def _inputs_line(settings: dict[str, Any]) -> str:
    """Which actuator, monitor calibration and interval calibration the diagnosis rests on (a
    recording of another actuator identified with the nominal one is otherwise silently off)."""
    params, cal = settings.get("params") or {}, settings.get("calibration") or {}
    uq = settings.get("uq_calibration")
    line = (
        f"actuator: {params.get('source', '?')} (hash {params.get('params_hash', '?')}); monitor calibration: "
        f"{cal.get('source', '?')} (made {cal.get('created') or 'in code'})"
    )
    return line + (f"; intervals: {uq['source']}" if uq else "")


def _second_search_line(second: dict[str, Any]) -> str:
    """Why the second search ran and which result was kept (its stage record)."""
    ratio = second["fitness_ratio"]
    kept = "its result kept" if second["taken"] else "the first search's result kept"
    return (
        f"second search: the first fit's NRMSE {100 * second['first_fit_nrmse']:.2f} % was above the monitor's "
        f"usual ({100 * second['trigger']:.3g} %); the second search's fitness "
        f"{'not finite' if ratio is None else f'{ratio:.3f} x the first'}: {kept}"
    )


def _switching_stage_line(stage: dict[str, Any]) -> str:
    """What the switching last stage did (the last stage's record, ``switching``)."""
    if "error" in stage:
        return f"switching last stage: not run ({stage['error']}); the search's estimate stands"
    moved = (
        f"the estimate of iterate {stage['iterate']} of {stage['iterations']} kept"
        if stage["taken"]
        else "the search's estimate fitted it best and stands"
    )
    if stage.get("stopped", "all iterations run") != "all iterations run":
        moved += f"; it stopped early: {stage['stopped']}"
    return (
        f"switching last stage: the switching model's eq. 3 {stage['start_fitness']:.4g} at the search's "
        f"estimate, {stage['fitness']:.4g} at the final one ({moved}); the fit above is that model's"
    )


def print_inspection(info: dict[str, Any]) -> None:
    """`emaphm inspect`: the file, its mapped channels (or the variables found), warnings, problems."""
    from rich.table import Table

    out = stdout_console()
    out.print(f"{info['file']}: {info['format']}, {info.get('size_bytes', 0) / 1e6:.1f} MB")
    if info.get("channels"):
        table = Table(title="mapped channels (min and max converted to SI)")
        for column in ("channel", "name", "file unit", "samples", "rate [Hz]", "duration [s]", "min", "max",
                       "equal samples at an extreme"):  # fmt: skip
            table.add_column(
                column, justify="right" if column in ("samples", "rate [Hz]", "duration [s]") else "left"
            )
        for role, ch in info["channels"].items():
            si = f" {ch['si_unit']}" if ch.get("si_unit") else ""
            sat = ch.get("saturation")
            table.add_row(
                role, str(ch.get("name")), str(ch.get("unit")), str(ch.get("samples")),
                f"{ch['rate_hz']:.6g}" if ch.get("rate_hz") else "-",
                f"{ch['duration_s']:.4g}" if ch.get("duration_s") is not None else "-",
                f"{ch['min_si']:.4g}{si}" if ch.get("min_si") is not None else "-",
                f"{ch['max_si']:.4g}{si}" if ch.get("max_si") is not None else "-",
                f"{sat['run']} at the {sat['at']} ({sat['value']:.4g}{si})" if sat else "",
            )  # fmt: skip
        out.print(table)
    else:
        table = Table(title="variables found")
        for column in ("name", "length", "type"):
            table.add_column(column)
        for v in info.get("variables", []):
            table.add_row(str(v.get("name")), str(v.get("length")), str(v.get("dtype")))
        out.print(table)
    for w in info.get("warnings", []):
        out.print(f"warning: {w}")
    for p in info.get("problems", []):
        out.print(f"problem: {p}")
    out.print("usable" if info["usable"] else "not usable")


def print_params(actuator: Any, source: str) -> None:
    """`emaphm params`: every parameter of `actuator` in use with its unit, the nominal value and its
    meaning (the inverter: control, V_dc and the keys of its control mode)."""
    import dataclasses

    from rich.markup import escape
    from rich.table import Table

    from ..calibration import params_hash
    from ..params import EmaParams, format_value

    nominal = EmaParams()
    table = Table(title=f"{source} (hash {params_hash(actuator)})")
    for column in ("block", "parameter", "value", "unit", "nominal", "meaning"):
        table.add_column(column, justify="right" if column in ("value", "nominal") else "left")
    for group in dataclasses.fields(actuator):
        mine, theirs = getattr(actuator, group.name), getattr(nominal, group.name)
        meta = {f.name: f.metadata for f in dataclasses.fields(mine)}
        for name in mine.fields_in_use():
            value, base = getattr(mine, name), getattr(theirs, name)
            shown = escape(format_value(value))
            shown = shown if value == base else f"[bold]{shown}[/bold]"
            table.add_row(
                group.name,
                name,
                shown,
                meta[name]["unit"],
                escape(format_value(base)),
                escape(meta[name]["doc"]),
            )
    stdout_console().print(table)


def print_thresholds(data: dict[str, Any], source: str) -> None:
    """`emaphm thresholds`: the threshold of each fault, what limits it, the requirements and healthy values."""
    from rich.table import Table

    reqs = {r["kind"]: r for r in data["requirements"]}

    def show(kind: str, value: float) -> str:
        return f"{value / reqs[kind]['scale']:.4g} {reqs[kind]['unit']}"

    table = Table(title=f"failure thresholds of {source}, {data['command']['type']} command")
    for column in ("fault", "threshold", "limited by", "at threshold", "worst case", "status"):
        table.add_column(column, justify="right" if column in ("threshold", "at threshold") else "left")
    for name, f in data["faults"].items():
        if f["threshold"] is None:
            table.add_row(
                name, "none", "-", "-", "-", f"{f['status']} (rul: placeholder {f['rul_placeholder']:g})"
            )
            continue
        kind = f["limited_by"]
        table.add_row(name, f"{f['threshold']:.4g}", kind, show(kind, f["at_threshold"][kind]),
                      f["case"] or "-", f["status"])  # fmt: skip
    out = stdout_console()
    out.print(table)
    out.print("requirements: " + ", ".join(f"{r['kind']} < {r['text']}" for r in data["requirements"]))
    out.print("healthy: " + ", ".join(f"{kind} {show(kind, v)}" for kind, v in data["healthy"].items()))
    out.print(
        f"{data['simulations']} HF simulations (noise off), {data['wall_time_s']:.1f} s; actuator {data['params_hash']}"
    )


def print_rul(data: dict[str, Any]) -> None:
    """`emaphm rul`: the RUL of each tracked fault, then the first failure."""
    from rich.table import Table

    def num(v: Any) -> str:
        return "beyond" if v is None else f"{v:.1f}"

    table = Table(
        title=f"actuator {data['actuator']} ({data['campaign']}), as of flight {data['at_flight']:g}"
        + (" (ProgPy UKF)" if data.get("estimator") == "ukf" else "")
    )
    for column in (
        "fault",
        "law",
        "threshold",
        "tracked from",
        "RUL median",
        "RUL 5-95 %",
        "P(fail before next)",
    ):
        table.add_column(column, justify="left" if column in ("fault", "law") else "right")
    for name, f in data["faults"].items():
        threshold = f"{f['threshold']:g}" + (" (placeholder)" if f["placeholder"] else "")
        if f["status"] != "tracked":
            table.add_row(name, f["law"], threshold, f["status"], "-", "-", "-")
            continue
        table.add_row(
            name, f["law"], threshold, str(f["tracked_from"]), num(f["rul_median"]),
            f"{num(f['rul_p05'])}-{num(f['rul_p95'])}", f"{f['prob_fail_before_next_inspection']:.2f}",
        )  # fmt: skip
    out = stdout_console()
    out.print(table)
    if data.get("doubtful_left_out"):
        out.print(
            f"{data['doubtful_left_out']} doubtful diagnos{'is' if data['doubtful_left_out'] == 1 else 'es'} left out "
            '(verdict "doubtful"; --include-doubtful to track them)'
        )
    first = data["first_failure"]
    if first["status"] == "tracked":
        out.print(
            f"first failure: median {num(first['rul_median'])} flights (5-95 % {num(first['rul_p05'])}-"
            f"{num(first['rul_p95'])}), most likely {first['most_likely_fault']}; P(before the next inspection in "
            f"{data['inspection_interval']:g} {data.get('unit', 'flights')}) {first['prob_fail_before_next_inspection']:.2f}"
        )
        if data.get("due"):
            from .render_fleet import due_text

            out.print(f"due: {due_text(data['due'])}")
        if first["placeholder_thresholds"]:
            out.print(f"placeholder thresholds (not limits): {', '.join(first['placeholder_thresholds'])}")
    else:
        out.print("no fault is tracked yet: nothing is predicted")
