"""``strapdown evaluate``: an estimator over the BROAD benchmark trials, with an optional grid search."""

from __future__ import annotations

import click

from ._options import (
    assignment,
    choice_option,
    estimators,
    param_name,
    param_option,
    parse_params,
    parse_value,
    scaled,
    writable_file,
)


@click.command()
@click.argument("folder", type=click.Path(exists=True, file_okay=False))
@click.option("-e", "--estimator", type=click.Choice(list(estimators())), default="tilt", show_default=True)
@click.option("--9d", "nine_d", is_flag=True, help="Give the estimator the magnetometer.")
@param_option("angles and rates also in degrees: NAME_deg=..., NAME_deg_s=....")
@click.option("-g", "--grid", multiple=True, metavar="NAME=V1,V2,...", help="Grid-search these values (repeatable).")
@choice_option("--objective", choices=("inclination", "total", "heading"), help="Mean RMSE the grid search ranks on.")
@choice_option(
    "--start",
    choices=("first-sample", "broad-example"),
    help="Initial attitude: the estimator's own, or BROAD's example code's (9D, to reproduce it).",
)
@click.option("--trials", default=None, help="Comma-separated trial names (default: every .mat in FOLDER).")
@click.option("--keep-heading-offset", is_flag=True, help="In 6D, do not remove the mean heading offset.")
@click.option("--csv", "csv_path", default=None, type=click.Path(dir_okay=False), help="Write per-trial rows here.")
def command(folder, estimator, nine_d, params, grid, objective, start, trials, keep_heading_offset, csv_path):
    """Run an estimator over the BROAD trials in FOLDER with one parameter set; print RMSE per trial and group.

    Errors follow the BROAD protocol (total, heading and inclination RMSE over the movement phases, in
    degrees).  With --grid, every combination is evaluated and ranked instead.

    \b
    Examples:
      strapdown evaluate broad/data_mat
      strapdown evaluate broad/data_mat -e mahony --9d -p kp=0.5 -p ki=0.001
      strapdown evaluate broad/data_mat -e madgwick --9d -p beta=0.12 -p variant=reference --start broad-example
      strapdown evaluate broad/data_mat -e tilt -g tau_acc=1,2,3 -g tau_bias=50,100
      strapdown evaluate broad/data_mat -e attitude -g bias_limit_deg_s=1,2,4
    """
    from ..evaluate.broad import load_trials
    from ..evaluate.evaluation import evaluate as run_evaluate
    from ..evaluate.evaluation import grid_search

    fixed = parse_params(estimator, params)
    if csv_path:
        writable_file(csv_path, "--csv")
    ranges = {}
    for a in grid:
        name, value = assignment(a, "--grid", raw=True)
        values = [parse_value(v) for v in value.split(",") if v.strip()]
        shown, (name, factor) = name, param_name(estimator, name, "--grid")  # bias_limit_deg_s=1,2: degrees
        defaults = _defaults(estimator)
        if name in defaults and not isinstance(defaults[name], str):
            words = [v for v in values if not isinstance(v, float)]
            if words:
                raise click.BadParameter(
                    f"{name} takes numbers, got {', '.join(map(repr, words))}", param_hint="--grid"
                )
        ranges[name] = [scaled(shown, v, factor, "--grid") for v in values]
    names = [t.strip() for t in trials.split(",") if t.strip()] if trials else None
    heading = False if keep_heading_offset else None
    try:
        data = load_trials(folder, names)
        if ranges:
            found = grid_search(
                estimator,
                data,
                ranges,
                params=fixed,
                mag=nine_d,
                start=start,
                objective=objective,
                heading_offset=heading,
            )
            click.echo(found.table())
            return
        result = run_evaluate(estimator, data, params=fixed, mag=nine_d, start=start, heading_offset=heading)
    except (ValueError, FileNotFoundError) as exc:
        raise click.UsageError(str(exc)) from None
    click.echo(result.table())
    if csv_path:
        try:
            result.to_csv(csv_path)
        except OSError as exc:  # a full disk: checked writable, still not written
            raise click.ClickException(f"cannot write {csv_path}: {exc}") from None
        click.echo(f"written: {csv_path}")


def _defaults(estimator: str) -> dict:
    import dataclasses

    params = estimators()[estimator][1]()
    return {f.name: getattr(params, f.name) for f in dataclasses.fields(params)}
