"""`emaphm campaign run` and `emaphm campaign status`: fleet campaigns (docs/campaigns.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError
from .output import campaign_progress, err
from .render_campaign import print_campaign_status

__all__ = ["campaign_app", "campaign_run", "campaign_status_command"]

MAX_FAILURE_LINES = 20  # failed jobs listed a line each after a run; the rest are counted


campaign_app = typer.Typer(
    help="Fleet campaigns: many identifications from one file, on Dask, into a results store (docs/campaigns.md).",
    no_args_is_help=True,
)


@campaign_app.command("run")
def campaign_run(
    spec: Annotated[Path, typer.Argument(help="Campaign file (TOML).")],
    out: Annotated[Path, typer.Option("--out", help="Folder of the results store (created if missing).")],
    scheduler: Annotated[
        str | None,
        typer.Option(
            help="Dask scheduler address (default: DASK_SCHEDULER_ADDRESS, else a local cluster); 'serial': no Dask."
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(help="Local worker processes, one numba thread each (default: one per core)."),
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print the summary as one JSON object.")] = False,
    keep_stale: Annotated[
        bool,
        typer.Option(
            "--keep-stale",
            help="Keep the stored results made by another version's code, data or settings instead of redoing them.",
        ),
    ] = False,
) -> None:
    """Run the jobs of a campaign that the store does not hold yet (a rerun completes an interrupted one).

    A stored result made by other code, packaged data or settings (another fingerprint) is redone,
    unless --keep-stale; the latest result of a job is the one read.

    Exit status 0 when every job is done, 1 when some failed: each is printed in one line, its
    traceback recorded in the store's failures; a rerun tries them again.
    """
    import json

    from ..campaign import load_campaign, run_campaign

    campaign = load_campaign(spec)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: exists and is not a folder")
    if not out.absolute().parent.is_dir():
        raise InputError(f"--out {out}: folder {out.absolute().parent} does not exist")
    from ..campaign.baselines import baseline_jobs

    waiting = [b for b in baseline_jobs(campaign, out) if not b.made()]
    if waiting:
        err.print(f"campaign {campaign.name}: making {len(waiting)} baseline(s) from healthy recordings first "
                  "(~10 s each on a core), then the identifications")  # fmt: skip
    with campaign_progress(campaign.name) as update:
        summary = run_campaign(
            campaign, out, scheduler=scheduler, workers=workers, progress=update, keep_stale=keep_stale
        )
    data = summary.to_json()
    if json_out:
        typer.echo(json.dumps(data))
    err.print(
        f"campaign {summary.campaign}: {summary.jobs} jobs, {summary.already_done} already done, "
        f"{summary.done} done now, {summary.failed} failed ({summary.backend}, {summary.wall_time_s:.1f} s); "
        f"store {out}"
    )
    if summary.baselines:
        err.print(f"{summary.baselines} baseline(s) made from the actuators' healthy recordings ({out}/baselines)")
    if summary.waiting:
        err.print(f"{len(summary.waiting)} actuator(s) wait for their baseline: {', '.join(summary.waiting[:10])}")
    if summary.stale:
        kept = "kept (--keep-stale)" if summary.kept_stale else "redone"
        err.print(f"{summary.stale} stored result(s) were made by other code, data or settings: {kept}")
    if summary.failed:
        for line in summary.failures[:MAX_FAILURE_LINES]:
            err.print(f"emaphm: failed: {line}", soft_wrap=True)
        more = summary.failed - MAX_FAILURE_LINES
        err.print(
            f"emaphm: {summary.failed} job(s) failed{f' ({more} more not shown)' if more > 0 else ''}; their "
            f"tracebacks are in the store ({out}/failures, column traceback): see 'emaphm campaign status {spec} {out}'",
            soft_wrap=True,
        )
        raise typer.Exit(1)


@campaign_app.command("status")
def campaign_status_command(
    spec: Annotated[Path, typer.Argument(help="Campaign file (TOML).")],
    out: Annotated[Path, typer.Argument(help="Folder of the results store.")],
    json_out: Annotated[bool, typer.Option("--json", help="Print the counts as one JSON object.")] = False,
) -> None:
    """Count the done, failed and missing jobs of a campaign in a results store."""
    import json

    from ..campaign import campaign_status

    data = campaign_status(spec, out)
    if json_out:
        typer.echo(json.dumps(data))
        return
    print_campaign_status(data)
