"""Driving ``checkpoint_worker.py`` from outside (stdlib only): the command of a 2-rank worker
run, and a checkpointed run whose rank 1 is killed with SIGKILL once a given step is reported.
Used by test_multiprocess.py and benchmarks/regression_figures.py."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

WORKER = Path(__file__).with_name("checkpoint_worker.py")


def worker_cmd(mode, directory, out, ranks: int = 2, stop_after=None) -> list:
    """``mpirun -n ranks`` of the worker in ``mode`` ("full", "checkpointed", "resume");
    ``stop_after``: a checkpointed run stops after that many increments."""
    return [shutil.which("mpirun"), "-n", str(ranks), sys.executable, str(WORKER), mode,
            str(directory), str(out)] + ([] if stop_after is None else [str(stop_after)])


def kill_checkpointed_run(directory, out, env, kill_after: int, timeout: float = 600):
    """Run the worker "checkpointed" into ``directory`` and SIGKILL its rank 1 once it reports
    step ``kill_after`` (stop reading after ``timeout`` s). Returns (the finished process, whether
    the kill was sent)."""
    proc = subprocess.Popen(worker_cmd("checkpointed", directory, out), env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    pids, killed = {}, False
    deadline = time.time() + timeout
    for line in proc.stdout:
        parts = line.split()
        if parts[:1] == ["PIDS"]:
            pids = {rank: int(p) for rank, p in enumerate(parts[1:])}
        elif parts[:1] == ["STEP"] and int(parts[1]) >= kill_after and not killed:
            os.kill(pids[1], signal.SIGKILL)
            killed = True
        if time.time() > deadline:
            break
    proc.wait(timeout=120)
    return proc, killed
