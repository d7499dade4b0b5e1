"""Study commands: validate, schema, metrics, run, report."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.text import Text

from ..errors import ParameterError
from .common import (
    JsonOpt,
    _emit,
    _fail,
    app,
    err,
    out,
)

StudyArg = Annotated[Path, typer.Argument(help="Study YAML file.")]


def _load_study(path: Path):
    from ..study import load_study

    try:
        return load_study(path)
    except ParameterError as exc:
        _fail(exc)
        raise  # unreachable


@app.command()
def validate(study_file: StudyArg, as_json: JsonOpt = False,
             check_space: Annotated[int, typer.Option(
                 help="designs sampled to estimate how much of the design box is "
                      "geometrically invalid (0: skip)", min=0, max=4096)] = 128) -> None:
    """Check a study file (exit 2 with the offending field on error; writes nothing)."""
    from ..runtime.memory import checking_for, require_command
    from ..study.optimisers import expected_evaluations

    with checking_for("run"):           # the budgets `pkmlab run` will check
        require_command("pkmlab run")
        study = _load_study(study_file)
    info = {"study": study.name, "file": str(study_file), "valid": True,
            "variables": [v.name for v in study.variables],
            "derived": [d.name for d in study.space.derived],
            "objectives": [f"{o.sense} {o.metric}" for o in study.objectives],
            "constraints": [c.describe() for c in study.constraints],
            "metrics": list(study.evaluation.metrics),
            "optimizer": study.optimizer.method,
            "evaluations": expected_evaluations(study.space, study.optimizer),
            "output": str(study.output), "warnings": []}
    if check_space:
        bad, reasons = study.space.validity(check_space, study.seed)
        info["invalid_fraction"] = bad
        if bad >= 0.2:
            info["warnings"].append(
                f"{100 * bad:.0f} % of {check_space} sampled designs are geometrically "
                "invalid (" + "; ".join(f"{n}× {r}" for r, n in reasons) + "): the optimiser "
                "will spend that share of its budget on them; narrow the ranges or "
                "parametrise coupled variables with 'derived' (docs/studies.md)")
    if as_json:
        _emit(info)
        return
    out.print(escape(f"{study_file}: valid — {len(info['variables'])} design variables, "
                     f"{len(info['objectives'])} objectives, {len(info['constraints'])} "
                     f"constraints, {info['optimizer']} (~{info['evaluations']} evaluations), "
                     f"output {info['output']}"), highlight=False)
    for w in info["warnings"]:
        err.print(escape(f"warning: {w}"), highlight=False)


@app.command()
def schema() -> None:
    """Print the JSON Schema of study files (for editors)."""
    from ..study import study_schema

    _emit(study_schema())


@app.command()
def metrics(as_json: JsonOpt = False) -> None:
    """List every study metric: unit, evaluate block, kind of number, meaning."""
    from ..study.evaluators.registry import metrics_markdown
    from ..study.metrics import METRICS

    if as_json:
        _emit({m.name: {"unit": m.unit, "evaluator": m.evaluator, "statistic": m.statistic,
                        "description": m.description} for m in METRICS.values()})
        return
    sys.stdout.write(metrics_markdown())


def _progress_bar(total: int):
    """A rich progress bar with rate and ETA on a terminal; without one (a log, CI, a batch
    job), a line on stderr every 5 s or every tenth of the candidates."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        ProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    class Rate(ProgressColumn):
        def render(self, task):
            return Text(f"{task.speed:.1f} candidates/s" if task.speed else "… candidates/s")

    if not err.is_terminal:
        from ..runtime.progress import ProgressLines

        return None, ProgressLines(total, sys.stderr)
    prog = Progress(TextColumn("evaluating"), BarColumn(), MofNCompleteColumn(), Rate(),
                    TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                    console=err, transient=True)
    task = prog.add_task("eval", total=total)
    return prog, (lambda n: prog.advance(task, n))


@contextlib.contextmanager
def _writing_into(folder: Path):
    """A file-system error without a path (a full disk while writing) names the results
    folder being written."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None:
            exc.filename = f"writing the results into {folder}"
        raise


@contextlib.contextmanager
def _estimate_lines():
    """The study's time estimate (logged by the optimiser module before the first candidate)
    as a ``pkmlab:`` line on stderr; the candidates' own log lines stay quiet."""
    import logging

    # and what the run compiles, one line per group of kernels (pkmlab.study.run before the
    # workers start, pkmlab.study.runners in a worker: the first run only)
    loggers = [logging.getLogger(n) for n in ("pkmlab.study.optimisers", "pkmlab.study.run",
                                              "pkmlab.study.runners", "pkmlab.runtime.jit")]
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("pkmlab: %(message)s"))
    old = [lg.level for lg in loggers]
    for lg in loggers:
        lg.addHandler(handler)
        lg.setLevel(logging.INFO)
    try:
        yield
    finally:
        for lg, level in zip(loggers, old):
            lg.removeHandler(handler)
            lg.setLevel(level)


@app.command()
def run(
    study_file: StudyArg,
    jobs: Annotated[int, typer.Option(help="parallel evaluations (joblib workers)")] = 1,
    resume: Annotated[bool, typer.Option(
        "--resume", help="continue the study in its output folder without repeating work")]
    = False,
    overwrite: Annotated[bool, typer.Option(
        "--overwrite", help="replace an earlier run in the output folder")] = False,
    backend: Annotated[str, typer.Option(help="loky | dask")] = "loky",
    scheduler: Annotated[str | None, typer.Option(help="Dask scheduler address")] = None,
    out_dir: Annotated[Path | None, typer.Option(
        "--out", help="output folder (default: the study's, results/<study>)")] = None,
    as_json: JsonOpt = False,
) -> None:
    """Run a design study: evaluate candidates, keep every result, report the Pareto set."""
    import time

    from ..runtime.progress import log_lines
    from ..study.folder import OutputLock, check_output
    from ..study.optimisers import expected_evaluations
    from ..study.report import export_designs, pareto_records, write_report
    from ..study.run import run_study
    from ..study.runners import make_runner
    from ..webreport import write_study_page

    study = _load_study(study_file)
    if out_dir is not None:
        study = study.with_output(out_dir)
    if resume and overwrite:
        _fail(ParameterError("--resume / --overwrite", "one of them", "both"))
    try:
        runner = make_runner(backend, jobs, scheduler)
    except ParameterError as exc:
        _fail(exc)
    prog, advance = _progress_bar(expected_evaluations(study.space, study.optimizer))
    outp = Path(study.output)
    # the folder stays locked until the report, the designs and the page are written: a second
    # run (--overwrite or --resume) or a report rebuild meanwhile is refused
    with contextlib.ExitStack() as held:
        t0 = time.perf_counter()
        try:
            check_output(outp, study.source, overwrite=overwrite)
            lock = held.enter_context(OutputLock(outp))
            if prog is not None:
                prog.start()
            with _estimate_lines():
                store = run_study(study, runner, resume=resume, overwrite=overwrite,
                                  progress=advance, lock=lock)
        except ParameterError as exc:
            _fail(exc)
        finally:
            if prog is not None:
                prog.stop()
            runner.close()
        elapsed = time.perf_counter() - t0
        records = store.all()
        store.close()
        with log_lines(), _writing_into(outp):
            t1 = time.perf_counter()
            info = write_report(outp, study, records)
            t2 = time.perf_counter()
            _, problems = export_designs(outp, study, pareto_records(study, records),
                                         records=records)
            t3 = time.perf_counter()
            page = write_study_page(outp, study, records)
    timings = {"evaluation_s": elapsed, "summary_s": t2 - t1, "export_s": t3 - t2,
               "page_s": time.perf_counter() - t3}
    info.update(seconds=elapsed, output=str(outp), export_problems=problems, report=str(page),
                timings_s=timings)
    if as_json:
        _emit(info)
        return
    pruned = (f", {info['pruned']} pruned by the tolerance ladder" if info["pruned"] else "")
    out.print(escape(f"{study.name}: {info['evaluations']} evaluations ({info['failed']} "
                     f"invalid or failed{pruned}) in {elapsed:.1f} s, {info['pareto']} Pareto "
                     "designs"),
              highlight=False)
    _print_markdown((outp / "summary.md").read_text())
    for p in problems:
        err.print(escape(f"warning: export skipped: {p}"), highlight=False)
    out.print(escape(f"results in {outp}/ (report.html, summary.md, pareto.csv, pareto.png, "
                     "evaluations.csv, designs/)"), highlight=False)
    out.print(escape(f"open {page.resolve().as_uri()} in a browser"), highlight=False)


def _open_results(results_dir: Path):
    """A results folder → ``(study, records)``, read-only."""
    from ..study import study_from_mapping
    from ..study.store import Store

    path = results_dir / "evaluations.sqlite"
    if not path.is_file():
        _fail(ParameterError("RESULTS_DIR", "a study results folder with evaluations.sqlite",
                             str(results_dir)))
    try:
        store = Store(path, read_only=True)
        resolved, records = store.get_meta("resolved"), store.all()
        store.close()
        study = study_from_mapping(resolved)
    except ParameterError as exc:
        _fail(exc)
    return study.with_output(results_dir), records


@app.command()
def report(results_dir: Annotated[Path, typer.Argument(help="a study's results folder")],
           as_json: JsonOpt = False) -> None:
    """Rebuild the tables, Pareto plot, summary and report.html from the store and the
    exported designs (no re-evaluation)."""
    from ..runtime.progress import log_lines
    from ..study.folder import OutputLock
    from ..study.report import write_report
    from ..webreport import write_study_page

    study, records = _open_results(results_dir)
    # not while a run writes there (the lock refuses, naming the run)
    with log_lines(), _writing_into(results_dir), OutputLock(results_dir):
        info = write_report(results_dir, study, records)
        info["report"] = str(write_study_page(results_dir, study, records))
    info["output"] = str(results_dir)
    if as_json:
        _emit(info)
        return
    out.print(escape(f"rebuilt {results_dir}: {info['evaluations']} evaluations, "
                     f"{info['pareto']} Pareto designs"), highlight=False)


def _print_markdown(text: str) -> None:
    """summary.md on the console: rendered (tables drawn) on a terminal; piped, the file's
    own lines, never hard-wrapped at the console width."""
    if out.is_terminal:
        from rich.markdown import Markdown

        out.print(Markdown(text))
    else:
        out.print(text, markup=False, highlight=False, soft_wrap=True, end="")
