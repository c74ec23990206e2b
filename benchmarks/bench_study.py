"""Throughput of a study on Dask (issue 13): 200 combinations, zero-order lobes and the FRF, 1 and 2 workers.

The study: 200 end mills (diameters 10 to 20 mm, overhangs 55 to 115 mm,
three to four teeth, explicit holder-tool joints), each in a catalogue BT40
ER32 chuck of its shank's bore (the built-in holder's 12 mm bore takes no
16 or 20 mm shank), on the built-in spindle,
one cut (aluminium 7075, 3 mm radial depth, down milling, 0.05 mm per
tooth, a 15 kW spindle), the tool point FRF on the assembly's 2,491 lines,
zero-order lobes on 441 speeds and the recommendation; no figures, results
written to a temporary directory as a run of the command does.

Printed (``bench: NAME VALUE``):

* ``study_200_zoa_frf_1_worker_per_s``, ``..._2_workers_per_s``: combinations
  per second on a local cluster of 1 and 2 worker processes (started and
  warmed up before the clock starts: the workers have imported the library);
* ``study_200_zoa_frf_scaling_2_over_1``: their ratio (2 is perfect);
* ``study_task_compute_s``: one combination computed in this process
  (``run_task``, median of 20), the cost a worker pays per task;
* ``study_worker_task_s_1_worker``, ``..._2_workers``: the mean time a task
  took in the workers (from the result files);
* ``study_overhead_per_task_s``: 1-worker wall time per task minus the
  worker's time per task: what Dask and this process (receiving and saving
  each result) add per task;
* ``study_driver_cpu_per_task_s_1_worker``, ``..._2_workers``: CPU time of
  this process (the client: submitting, receiving, saving, the table) per task;
* ``study_local_cluster_start_2_workers_s``: starting the 2-worker cluster.
"""

from __future__ import annotations

import json
import logging
import statistics
import tempfile
import time
import warnings
from pathlib import Path


def _study(n: int):
    from substructure.study import Combination, Compute, Cut, Machine, Study

    combos = []
    for i in range(n):
        d = (10, 12, 16, 20)[i % 4]
        overhang = 55 + (i * 13) % 61
        k = 1.2e7 * (d / 12) ** 2 * (80 / overhang) ** 1.5
        combos.append(Combination(f"tool {i:03d}", tool={"diameter": f"{d} mm", "overhang": f"{overhang} mm",
                                                          "flute_length": f"{min(2 * d, overhang - 10)} mm",
                                                          "teeth": 3 + i % 2},
                                  holder={"catalog": "BT40 ER32", "bore": f"{d} mm"},
                                  joint={"k": {"yf": f"{k!r} N/m"}}))
    return Study("bench", [Machine("bench", limits={"max_speed": "24000 rpm", "power": "15 kW"})], combos,
                 [Cut("aluminium", workpiece="aluminium-7075", radial_depth="3 mm", milling="down",
                      feed_per_tooth="0.05 mm")], Compute(lobes=["zoa"], figures=False, band=False))


def _cluster(n: int):
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                           scheduler_kwargs={"dashboard_address": ":0"}, silence_logs=logging.ERROR,
                           env={"SUBSTRUCTURE_NUM_THREADS": "1"})
    return cluster, Client(cluster, set_as_default=False)


def _throughput():
    from substructure.study.task import run_task

    study = _study(200)
    warm = _study(4)
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tasks = study.tasks()[:20]
        run_task(tasks[0])
        times = []
        for task in tasks:
            t0 = time.perf_counter()
            run_task(task)
            times.append(time.perf_counter() - t0)
        out["study_task_compute_s"] = statistics.median(times)
        for workers in (1, 2):
            t0 = time.perf_counter()
            cluster, client = _cluster(workers)
            if workers == 2:
                out["study_local_cluster_start_2_workers_s"] = time.perf_counter() - t0
            try:
                warm.run(client, progress=False)  # imports and caches in the workers
                with tempfile.TemporaryDirectory() as folder:
                    t0, cpu = time.perf_counter(), time.process_time()
                    table = study.run(client, out=folder, progress=False)
                    elapsed, cpu = time.perf_counter() - t0, time.process_time() - cpu
                    spent = [json.loads(p.read_text())["elapsed_s"] for p in Path(folder, "results").iterdir()]
                failed = table[table["status"] != "ok"]
                assert failed.empty, f"{len(failed)} combinations failed, e.g. {failed['error'].iloc[0]}"
            finally:
                client.close()
                cluster.close()
            name = "1_worker" if workers == 1 else "2_workers"
            out[f"study_200_zoa_frf_{name}_per_s"] = 200 / elapsed
            out[f"study_worker_task_s_{name}"] = statistics.mean(spent)
            out[f"study_driver_cpu_per_task_s_{name}"] = cpu / 200
    out["study_200_zoa_frf_scaling_2_over_1"] = (out["study_200_zoa_frf_2_workers_per_s"]
                                                 / out["study_200_zoa_frf_1_worker_per_s"])
    out["study_overhead_per_task_s"] = (1 / out["study_200_zoa_frf_1_worker_per_s"]
                                        - out["study_worker_task_s_1_worker"])
    return out


_throughput.names = ("study_200_zoa_frf_1_worker_per_s", "study_200_zoa_frf_2_workers_per_s",
                     "study_200_zoa_frf_scaling_2_over_1", "study_task_compute_s", "study_overhead_per_task_s",
                     "study_local_cluster_start_2_workers_s", "study_worker_task_s_1_worker",
                     "study_worker_task_s_2_workers", "study_driver_cpu_per_task_s_1_worker",
                     "study_driver_cpu_per_task_s_2_workers")


def figures():
    yield ("study_200_zoa_frf", _throughput)
