"""Running a study: tasks on Dask (or in this process), each result saved as it completes, progress, resume.

* **Where the tasks run.**  ``processes:N``: a local Dask cluster of N
  worker processes with one thread each (a crash of one loses one task);
  ``local:N``: N worker threads in this process; an address: an existing
  scheduler (``dask scheduler`` and ``dask worker`` on a cluster); a
  ``dask.distributed.Client``: its cluster; ``serial``: this process,
  without Dask.  A local cluster is made for the run and closed after it.
* **Nothing lost.**  The worker returns plain data; this process writes the
  combination's figure and FRF, then its result file
  ``results/KEY.json`` (each atomically), as soon as the task completes.
  The result file is written last, so a combination counts as finished only
  when all its files are there.
* **Nothing repeated.**  ``resume`` keeps every result whose fingerprint
  (a hash of all its inputs) matches the task, and computes the others:
  those never finished, those lost with a worker, and those whose inputs
  changed.  The table is always assembled from the saved results, in the
  study's order, so that a resumed study gives the same table as an
  uninterrupted one.
* **A bad combination fails its rows.**  :func:`~substructure.study.task.run_task`
  turns every problem of a combination into failed rows with the message; a
  worker that dies (killed, out of memory) is retried by Dask
  (``distributed.scheduler.allowed-failures``) and then reported as
  ``crashed`` rows.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import re
import signal
import sys
import threading
import time
import warnings
from pathlib import Path
from typing import Any

from .._json import json_text
from ..errors import InvalidValueError, OutputExistsError, SubstructureWarning
from ..units import finite_real

__all__ = ["run_study", "Progress", "parse_scheduler", "json_text", "RESULT_FORMAT", "study_identity"]

#: The ``format`` of a combination's result file.
RESULT_FORMAT = "substructure-study-result/1"
_TABLE_FILES = ("table.parquet", "table.csv", "summary.png")
_FOLDERS = ("results", "figures", "frf")


def parse_scheduler(text: str) -> tuple[str, Any]:
    """``processes:N``, ``local:N``, ``serial`` or a scheduler's address, checked.

    Parameters
    ----------
    text : str
        The scheduler as the command line or :meth:`Study.run` takes it;
        ``processes`` and ``local`` alone use one worker per CPU.

    Returns
    -------
    (str, object)
        ``("processes", N)``, ``("local", N)``, ``("serial", None)`` or
        ``("address", text)``.
    """
    if not isinstance(text, str) or not text.strip():
        raise InvalidValueError(f"scheduler: got {text!r}; expected processes:N, local:N, serial or an address")
    text = text.strip()
    if text == "serial":
        return "serial", None
    kind, sep, count = text.partition(":")
    if kind in ("processes", "local"):
        if not sep:
            return kind, _cpus()
        try:
            n = int(count)
        except ValueError:
            n = 0
        if not 1 <= n <= 4096:
            raise InvalidValueError(f"scheduler: got {text!r}; expected {kind}:N with N workers, 1 to 4096")
        return kind, n
    if re.fullmatch(r"[a-z]+://\S+", text) or re.fullmatch(r"[A-Za-z0-9.\-\[\]:]+:\d{2,5}", text):
        return "address", text
    raise InvalidValueError(f"scheduler: got {text!r}; expected processes:N, local:N, serial or a scheduler's "
                            "address such as tcp://10.0.0.5:8786 or 10.0.0.5:8786")


def _cpus() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


class Progress:
    """Progress lines: done / total, failures, the rate and the time left.

    Parameters
    ----------
    stream : file-like or None
        Where the lines go (``None``: nowhere).
    total : int
        Tasks in the study.
    resumed : int
        Tasks found finished before the run.
    interval : float, default 2.0
        Seconds between lines (the first and the last are always printed).
    """

    def __init__(self, stream: Any, total: int, resumed: int = 0, interval: float = 2.0):
        self.stream, self.total, self.resumed, self.interval = stream, total, resumed, interval
        self.done, self.failed, self.start, self.last = resumed, 0, time.perf_counter(), -1e9

    def say(self, text: str) -> None:
        """Print one line.

        Parameters
        ----------
        text : str
            The line, without the ``study:`` prefix.
        """
        if self.stream is not None:
            print(f"study: {text}", file=self.stream, flush=True)

    def update(self, failed_rows: int) -> None:
        """Count one finished task.

        Parameters
        ----------
        failed_rows : int
            Rows of the task that failed.
        """
        self.done += 1
        self.failed += failed_rows
        now = time.perf_counter()
        if now - self.last >= self.interval or self.done == self.total:
            self.last = now
            self.say(self.line(now))

    def line(self, now: float | None = None) -> str:
        """The progress line.

        Parameters
        ----------
        now : float, optional
            ``time.perf_counter()`` of the line.

        Returns
        -------
        str
            ``"37/200 done, 1 row failed; 3.1/s, about 53 s left"``.
        """
        now = time.perf_counter() if now is None else now
        elapsed = max(now - self.start, 1e-9)
        fresh = self.done - self.resumed
        rate = fresh / elapsed
        text = f"{self.done}/{self.total} done"
        if self.failed:
            text += f", {self.failed} row{'s' if self.failed > 1 else ''} failed"
        if self.done == self.total:
            return text + f" in {elapsed:.1f} s" + (f" ({rate:.3g} combinations/s)" if fresh else "")
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        return text + f"; {rate:.3g} combinations/s, about {_duration(left)} left"


def _duration(seconds: float) -> str:
    if seconds != seconds:
        return "? s"
    if seconds < 100:
        return f"{seconds:.0f} s"
    if seconds < 6000:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


class _Store:
    """The output directory: a result file per combination, its figure and FRF, the table."""

    def __init__(self, out: Any, inputs: tuple):
        self.root = Path(out)
        self.inputs = {Path(os.path.abspath(p)).resolve(): os.fspath(p) for p in inputs}
        if self.root.exists() and not self.root.is_dir():
            raise InvalidValueError(f"out: {self.root} is a file; expected a directory (it is created if missing)")

    def path(self, folder: str, key: str, suffix: str) -> Path:
        return self.root / folder / f"{key}{suffix}"

    def check(self, tasks: list[dict], resume: bool, overwrite: bool) -> None:
        planned = [self.root / name for name in _TABLE_FILES]
        planned += [self.path(f, t["key"], s) for t in tasks for f, s in (("results", ".json"),
                                                                         ("figures", ".png"), ("frf", ".csv"))]
        for p in planned:
            where = Path(os.path.abspath(p)).resolve()
            if where in self.inputs:
                raise InvalidValueError(f"out: {p} would be written onto the input {self.inputs[where]}; choose "
                                        "another output directory")
        if resume or overwrite:
            self.clean()
        if resume or overwrite or not self.root.exists():
            return
        found = [p for p in planned if p.exists()]
        if found:
            raise OutputExistsError(f"{self.root}: holds the files of a study ({found[0].relative_to(self.root)}, "
                                    f"{len(found)} in all); continue it with --resume (resume=True) or compute it "
                                    "anew with --overwrite (overwrite=True)")

    def clean(self) -> None:
        """Remove temporary files of this study's that a killed run left (``.NAME.XXXX.part.SUFFIX``)."""
        for folder in _FOLDERS:
            for p in (self.root / folder).glob(".*.part.*") if (self.root / folder).is_dir() else ():
                p.unlink(missing_ok=True)
        for p in self.root.glob(".*.part.*") if self.root.is_dir() else ():
            if any(p.name.startswith(f".{name}.") for name in _TABLE_FILES):
                p.unlink(missing_ok=True)

    def load(self, task: dict, problems: list[str] | None = None) -> dict | None:
        """The saved result of ``task`` if it is this task's and whole; else None (``problems`` says why)."""
        from ..io import read_text

        path = self.path("results", task["key"], ".json")
        if not path.exists():  # a combination never finished
            return None
        try:  # the checked read: a FIFO or a huge file put there is not a result (FileFormatError is a ValueError)
            text = read_text(path, "study result")
        except (OSError, ValueError) as exc:
            if problems is not None:
                problems.append(f"{path}: {' '.join(str(exc).split())}; not trusted, computed again")
            return None
        try:
            data = json.loads(text)
        except ValueError as exc:
            if problems is not None:
                problems.append(f"{path}: not a whole result file (cut short or edited: {exc}); not trusted, "
                                "computed again")
            return None
        if not isinstance(data, dict):
            if problems is not None:
                problems.append(f"{path}: not a result file (a JSON {type(data).__name__}, expected an object); "
                                "not trusted, computed again")
            return None
        if (data.get("format") != RESULT_FORMAT
                or data.get("fingerprint") != task["fingerprint"] or data.get("status") != "done"):
            return None
        why = _rows_problem(data.get("rows"), task)
        if why:
            if problems is not None:
                problems.append(f"{path}: {why}; not trusted, computed again")
            return None
        return data

    def load_all(self, tasks: list[dict], finished: dict, problems: list[str] | None = None) -> None:
        """Put the saved results of the tasks not in ``finished`` into it (:meth:`load`)."""
        for task in tasks:
            if task["key"] not in finished:
                record = self.load(task, problems)
                if record is not None:
                    finished[task["key"]] = record

    def other_study(self, identity: dict) -> str:
        """What another study's results in ``results/`` are (name, or the grid that differs), or ``""``.

        Every result file records the study it belongs to (``study``: its
        name and grid); files without it (older ones) or unreadable ones say
        nothing here.
        """
        from ..io import read_text

        folder = self.root / "results"
        for path in sorted(folder.glob("*.json")) if folder.is_dir() else ():
            try:
                held = json.loads(read_text(path, "study result")).get("study")
            except (OSError, ValueError, AttributeError):
                continue
            if not isinstance(held, dict) or held == identity:
                continue
            name = held.get("name")
            if name != identity["name"]:
                return f"study {name!r} ({path.name})"
            return f"study {name!r} on another grid ({_grid_text(held.get('grid'))}; {path.name})"
        return ""

    def save(self, result: dict, identity: dict | None = None) -> dict:
        from ..io import write_bytes, write_text

        key = result["key"]
        for folder in _FOLDERS:
            if folder == "results" or result.get(folder.rstrip("s")) is not None:
                (self.root / folder).mkdir(parents=True, exist_ok=True)
        record = {k: v for k, v in result.items() if k not in ("figure", "frf")}
        record["format"] = RESULT_FORMAT
        if identity is not None:
            record["study"] = identity
        if result.get("figure") is not None:
            write_bytes(self.path("figures", key, ".png"), result["figure"])
            record["figure"] = f"figures/{key}.png"
        if result.get("frf") is not None:
            _write_frf(result["frf"], self.path("frf", key, ".csv"))
            record["frf"] = f"frf/{key}.csv"
        write_text(self.path("results", key, ".json"), json_text(record) + "\n")  # last: the combination is done
        return record


def _grid_text(grid: Any) -> str:
    """A study's grid as a result file records it, in words: ``frequency 100 Hz to 5000 Hz by 10 Hz, ...``."""
    if not isinstance(grid, dict):
        return "not recorded"
    parts = []
    for key, value in grid.items():
        if isinstance(value, list) and len(value) == 3:
            parts.append(f"{key} {value[0]} to {value[1]} by {value[2]}")
        elif value is None:
            parts.append(f"{key} default")
    return ", ".join(parts) or "not recorded"


def study_identity(study) -> dict:
    """What tells a study's results from another's in one output directory: its name and its grid.

    Parameters
    ----------
    study : Study
        The study.

    Returns
    -------
    dict
        ``{"name": str, "grid": {"frequency": [...] or None, "speeds":
        [...], "sdm_speeds": [...] or None}}``, plain data.
    """
    import attrs

    grid = {k: None if v is None else list(v) for k, v in attrs.asdict(study.grid).items()}
    return json.loads(json_text({"name": study.name, "grid": grid}))


def _rows_problem(rows: Any, task: dict) -> str:
    """Why a result file's ``rows`` are not this combination's rows (one per cut, in order), or ``""``."""
    cuts = [spec["name"] for spec in task["cuts"]] or [""]
    if not isinstance(rows, list) or not all(isinstance(row, dict) for row in rows):
        return f"no 'rows' list of objects (expected one row per cut: {len(cuts)})"
    got = [row.get("cut") for row in rows]
    keys = {row.get("key") for row in rows}
    if got != cuts or keys != {task["key"]}:
        doubled = sorted({str(c) for c in got if got.count(c) > 1})
        return (f"{len(rows)} rows for {len(cuts)} cut{'s' if len(cuts) != 1 else ''} ({', '.join(map(repr, cuts))})"
                + (f", repeated: {', '.join(doubled)}" if doubled else "")
                + ("" if keys == {task["key"]} else f", rows of other combinations ({len(keys - {task['key']})})"))
    specs = task["cuts"] or [None]
    for row, spec in zip(rows, specs):
        why = _row_problem(row, task, spec)
        if why:
            return f"row of cut {row.get('cut')!r}: {why}" if task["cuts"] else f"its row: {why}"
    return ""


#: Statuses a finished result's rows may have (crashed and pending rows are never saved as done).
_SAVED_STATUSES = ("ok", "failed")
_POSITIVE = ("tool_diameter_m", "overhang_m", "flute_length_m", "spindle_speed_rpm", "window_lo_rpm", "window_hi_rpm",
             "runner_up_speed_rpm", "tool_mode_hz", "tool_mode_lo_hz", "tool_mode_hi_hz", "radial_depth_m",
             "feed_per_tooth_m", "kt_pa", "teeth", "band_members")
_NON_NEGATIVE = ("depth_m", "limit_depth_m", "zoa_min_limit_m", "zoa_absolute_limit_m", "sdm_min_limit_m",
                 "runner_up_depth_m", "mrr_m3_per_s", "power_w", "torque_n_m", "structure_band_lo_hz",
                 "chatter_frequency_hz", "tool_mode_compliance_m_per_n", "kn_pa")


def _row_problem(row: dict, task: dict, spec: dict | None) -> str:
    """Why one saved row is not one the study could have written (a hand edit), or ``""``."""

    from .table import COLUMNS

    if row.get("status") not in _SAVED_STATUSES:
        return f"status: got {row.get('status')!r}; expected {' or '.join(map(repr, _SAVED_STATUSES))}"
    if row.get("combination") != task["combination"] or row.get("machine") != task["machine"]["name"]:
        return (f"combination, machine: got {row.get('combination')!r}, {row.get('machine')!r}; expected "
                f"{task['combination']!r}, {task['machine']['name']!r}")
    for name, kind, _ in COLUMNS:
        value = row.get(name)
        if value is None:
            continue
        if kind == "str":
            ok = isinstance(value, str)
            expected = "a string"
        elif kind == "int":
            ok = isinstance(value, int) and not isinstance(value, bool)
            expected = "a whole number"
        else:
            ok = isinstance(value, (int, float)) and finite_real(value)
            expected = "a finite number or null"
        if ok and name in _POSITIVE:
            ok, expected = value > 0, "a positive number or null"
        elif ok and name in _NON_NEGATIVE:
            ok, expected = value >= 0, "a number >= 0 or null"
        if not ok:
            return f"{name}: got {value!r}; expected {expected}"
    if row["status"] == "failed" and not row.get("error"):
        return "status: 'failed' without an error"
    if row["status"] == "ok" and row.get("error"):
        return f"status: 'ok' with an error ({row['error']!r})"
    depth, limit = row.get("depth_m"), row.get("limit_depth_m")
    if depth is not None and limit is not None and depth > limit * (1 + 1e-9):
        return f"depth_m: got {depth!r}; above the row's stability limit limit_depth_m = {limit!r}"
    deepest = row.get("flute_length_m")
    if spec is not None and spec.get("max_depth") is not None:
        from ..units import Q_

        deepest = float(Q_(spec["max_depth"]).m_as("m"))
    if depth is not None and deepest is not None and depth > deepest * (1 + 1e-9):
        return (f"depth_m: got {depth!r}; deeper than the largest depth {deepest!r} m (the cut's max_depth, or the "
                "tool's flute length)")
    return ""


def _write_frf(data: dict, path: Path) -> None:
    import numpy as np

    from ..frf import FRF, Frequency
    from ..io.frf_files import write_csv

    values = np.asarray(data["real"]) + 1j * np.asarray(data["imag"])
    frf = FRF.single(Frequency.from_hz(np.asarray(data["frequency_hz"])), values, output=data["label"],
                     input=data["label"])
    write_csv(frf, path, overwrite=True)  # the study's own store (StudyStore.check guards the user's files)


def _crashed(task: dict, exc: BaseException) -> dict:
    what = " ".join(str(exc).split())
    message = (f"{task['where']}: the worker computing it was lost ({type(exc).__name__}"
               + (f": {what}" if what else "") + "); --resume (resume=True) tries it again")
    return {"key": task["key"], "fingerprint": task["fingerprint"], "status": "crashed",
            "rows": _status_rows(task, "crashed", message), "figure": None, "frf": None, "elapsed_s": None}


def _status_rows(task: dict, status: str, message: str = "") -> list[dict]:
    """The rows of a task not computed (one per cut), with this status and message."""
    from .task import _failed_row

    return [{**_failed_row(task, spec, message), "status": status} for spec in (task["cuts"] or [None])]


def _serial(tasks: list[dict]):
    from .task import run_task

    for task in tasks:
        yield task, run_task(task)


def _on_dask(client, tasks: list[dict]):
    from distributed import as_completed

    from .task import run_task

    futures = {client.submit(run_task, task, key=f"substructure-study-{task['fingerprint'][:24]}", pure=False): task
               for task in tasks}
    try:
        for future in as_completed(list(futures), loop=client.loop):
            task = futures.pop(future)
            try:
                result = future.result()
            except Exception as exc:  # the worker died (KilledWorker), the task was cancelled, ...
                result = _crashed(task, exc)
            future.release()
            yield task, result
    finally:
        if futures:
            try:
                client.cancel(list(futures))
            except RuntimeError:  # the client's loop already closed (an interruption): nothing left to cancel
                pass


def _local_cluster(kind: str, n: int, progress: Progress):
    import logging

    from distributed import Client, LocalCluster

    extra = {"env": {"SUBSTRUCTURE_NUM_THREADS": "1"}} if kind == "processes" else {}
    if importlib.util.find_spec("bokeh") is not None:
        extra["dashboard_address"] = _dashboard_address()
    else:  # no dashboard; the scheduler's HTTP server (health, metrics) on any free port, not on a busy 8787
        extra.update(dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"})
    # the cluster's own logs stay quiet: what a user needs of them (a lost worker, a failed combination) is in the
    # rows and the progress lines; an interruption closes the scheduler under busy workers, whose heartbeats
    # would log tracebacks
    with _workers_ignore_ctrl_c(kind == "processes"):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=kind == "processes",
                               silence_logs=logging.CRITICAL, **extra)
    client = Client(cluster, set_as_default=False)
    where = "worker processes" if kind == "processes" else "worker threads in this process"
    progress.say(f"local Dask cluster: {n} {where}")
    return cluster, client


@contextlib.contextmanager
def _workers_ignore_ctrl_c(processes: bool):
    """Worker processes started inside ignore SIGINT: Ctrl-C in a terminal reaches the whole process group, and
    only this process (which saves, says what is saved and closes the cluster) should hear it; workers started
    with SIGINT ignored keep ignoring it (Python installs no handler then), so none prints a traceback."""
    if not processes or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _dashboard_address() -> str:
    """Dask's usual port 8787 when it is free, else any free port (so that no warning is needed)."""
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        try:
            probe.bind(("", 8787))
        except OSError:
            return ":0"
    return ":8787"


def _dashboard(client, progress: Progress) -> None:
    link = getattr(client, "dashboard_link", None)
    if link and importlib.util.find_spec("bokeh") is not None:
        progress.say(f"Dask dashboard: {link}")
    else:
        progress.say("Dask dashboard: not available here (it needs bokeh: pip install bokeh)")


def run_study(study, client: Any = None, out: Any = None, scheduler: str | None = None, resume: bool = False,
              overwrite: bool = False, progress: Any = True):
    """Run a study: :meth:`substructure.study.Study.run`, whose documentation gives the arguments."""
    if resume and overwrite:
        raise InvalidValueError("resume and overwrite: choose one (resume keeps finished combinations, overwrite "
                                "computes everything anew)")
    if client is not None and scheduler is not None:
        raise InvalidValueError("client and scheduler: give one")
    stream = (sys.stderr if progress is True else None if progress in (False, None) else progress)
    kind, count = parse_scheduler(scheduler) if scheduler is not None else (None, None)
    tasks = study.tasks()
    if out is None:  # nowhere to put figures and FRF files: not made (the rows do not depend on them)
        tasks = [{**t, "compute": {**t["compute"], "figures": False, "frf_files": False}} for t in tasks]
    store = None if out is None else _Store(out, study.inputs)
    finished: dict[str, dict] = {}
    identity = study_identity(study)
    if store is not None:
        store.check(tasks, resume, overwrite)
        other = store.other_study(identity) if resume else ""
        if other:
            raise OutputExistsError(
                f"{store.root}: holds the results of {other}, not of the study given ({study.name!r}, "
                f"{_grid_text(identity['grid'])}); --resume (resume=True) continues the same study only: choose "
                "another --out (out) for it, or replace those results with --overwrite (overwrite=True)")
        if resume:
            problems: list[str] = []
            store.load_all(tasks, finished, problems)
            for problem in problems:  # a result file edited or cut short by hand: never a row twice or a crash
                warnings.warn(f"resume: {problem}", SubstructureWarning, stacklevel=2)
        store.root.mkdir(parents=True, exist_ok=True)
    todo = [t for t in tasks if t["key"] not in finished]
    report = Progress(stream, len(tasks), resumed=len(finished))
    report.say(f"{study.name!r}: {len(tasks)} combination{'s' if len(tasks) != 1 else ''} on their machines, "
               f"{len(study.cuts)} cut{'s' if len(study.cuts) != 1 else ''}"
               + (f"; {len(finished)} finished before, {len(todo)} to compute" if resume else ""))
    cluster = own = None
    try:
        if todo:
            if client is None and kind is None:
                try:
                    from distributed import default_client

                    client = default_client()
                except (ImportError, ValueError):  # threads: safe in any script (processes need a main guard)
                    kind, count = "local", _cpus()
            if kind == "serial":
                results = _serial(todo)
            else:
                if client is None and kind in ("processes", "local"):
                    cluster, own = _local_cluster(kind, count, report)
                elif client is None:
                    from distributed import Client

                    try:
                        own = Client(count, set_as_default=False)
                    except (OSError, TimeoutError) as exc:
                        raise InvalidValueError(f"scheduler: cannot reach the Dask scheduler at {count} "
                                                f"({exc})") from None
                    report.say(f"Dask scheduler at {count}")
                _dashboard(own or client, report)
                results = _on_dask(own or client, todo)
            for task, result in results:
                record = store.save(result, identity) if store is not None else {k: v for k, v in result.items()
                                                                         if k not in ("figure", "frf")}
                finished[task["key"]] = json.loads(json_text(record))
                report.update(sum(row["status"] != "ok" for row in result["rows"]))
        elif tasks:
            report.say("every combination was finished before; assembling the table")
    except KeyboardInterrupt:
        if store is not None:  # a result saved just as the signal came is on disk, if not yet counted here
            store.load_all(tasks, finished)
        message = (f"interrupted: {len(finished)} of {len(tasks)} combinations saved"
                   + (f" in {store.root}; --resume (resume=True) to continue" if store else " (no output directory)"))
        report.say(message)
        if store is not None:
            _assemble(study, tasks, finished, store)
        raise KeyboardInterrupt(message) from None
    finally:
        if own is not None:
            own.close()
        if cluster is not None:
            cluster.close()
    return _assemble(study, tasks, finished, store)


def _assemble(study, tasks: list[dict], finished: dict, store: _Store | None):
    from .table import make_table, summary_figure, write_table

    rows = []
    for task in tasks:
        record = finished.get(task["key"])
        rows += record["rows"] if record is not None else _status_rows(task, "pending")
    table = make_table(rows)
    if store is not None:
        write_table(table, store.root / "table.parquet", store.root / "table.csv")
        if rows:
            from ..io import replacing

            fig = summary_figure(table, title=f"{study.name}: combinations ranked")
            with replacing(store.root / "summary.png") as temporary:
                fig.savefig(temporary, format="png", dpi=100)
    return table
