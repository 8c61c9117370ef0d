"""The worker processes of a Dask LocalCluster (raytrace.executors.dask_client: the global
search's starts, the Monte Carlo's chunks) and of the global search's process pool leave to the
parent the same warnings (raytrace.executors.WORKER_QUIET_WARNINGS): a glass evaluated outside
its range and a kernel cache that cannot be written. The parent says each once, in one line; a
review found Dask's workers repeating them at every evaluation, in raw multi-line form, on the
parent's terminal (the pool's initializer ignored them, the Dask preload did not).

Each test runs in a child process: the preload hook ignores SIGINT, and the cluster's workers
write to the child's stderr, which the test reads."""

from __future__ import annotations

import subprocess
import sys
import warnings

import pytest

from raytrace.executors import WORKER_QUIET_WARNINGS, ignore_worker_warnings


def test_the_list_names_warning_categories():
    # a wrong name would fail every worker's start (the preload raises), not a test
    import importlib

    found = {getattr(importlib.import_module(m), n) for m, n in WORKER_QUIET_WARNINGS}
    assert all(issubclass(c, Warning) for c in found)
    from raytrace.kernels.jit import KernelCacheWarning
    from raytrace.materials import OutOfRangeWarning

    assert found == {OutOfRangeWarning, KernelCacheWarning}
    with warnings.catch_warnings():  # the filters put back after the test
        ignore_worker_warnings()
        for c in found:
            assert ("ignore", None, c, None, 0) in warnings.filters


#: the set-up each kind of worker runs: the Dask preload hook and the process pool's initializer
WORKER_SETUPS = {
    "dask preload": ("from raytrace.executors import dask_setup", "dask_setup(None)"),
    "process pool": (
        "from raytrace.optimize.global_search import _init_worker",
        "_init_worker(None, None)",
    ),
}


@pytest.mark.parametrize("setup", sorted(WORKER_SETUPS))
def test_a_worker_set_up_ignores_what_workers_leave_to_the_parent(setup):
    # the set-up as a worker runs it (no cluster, no pool): warned before it, silent after it;
    # another warning still shows
    imp, call = WORKER_SETUPS[setup]
    code = (
        "import warnings\n"
        f"{imp}\n"
        "from raytrace.kernels.jit import KernelCacheWarning\n"
        "from raytrace.materials import model_glass\n"
        "model_glass(1.6, 40.0).index(1550.0)\n"  # before: warns
        "warnings.warn('no cache (before)', KernelCacheWarning)\n"
        f"{call}\n"
        "model_glass(1.61, 41.0).index(1550.0)\n"
        "warnings.warn('no cache (in a worker)', KernelCacheWarning)\n"
        "warnings.warn('control (in a worker)', UserWarning)\n"
        "print('ok')\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "ok"
    # a warning's header line, "<string>:N: Category: message" (Python 3.13 prints the source
    # line of -c code under it too, which names the category again without the colon)
    assert r.stderr.count("OutOfRangeWarning:") == 1 and "1.6/40" in r.stderr
    assert r.stderr.count("KernelCacheWarning:") == 1 and "(before)" in r.stderr
    assert "control (in a worker)" in r.stderr


CLUSTER = """
import warnings
from raytrace.executors import dask_client
from raytrace.kernels.jit import KernelCacheWarning
from raytrace.materials import model_glass


def glass():
    return float(model_glass(1.6, 40.0).index(1550.0))


if __name__ == "__main__":
    client, close = dask_client("local:1")
    try:
        tasks = [
            client.submit(glass, pure=False),
            client.submit(warnings.warn, "no cache (in a worker)", KernelCacheWarning, pure=False),
            client.submit(warnings.warn, "control (in a worker)", UserWarning, pure=False),
        ]
        for t in tasks:
            t.result()
    finally:
        close()
    print("ok")
"""


def _run_ok(script, code: str, timeout: float) -> subprocess.CompletedProcess:
    """Run ``code`` as the script ``script`` in a fresh Python; it must end with "ok"."""
    script.write_text(code)
    r = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=timeout, check=False
    )
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr
    return r


def test_local_cluster_workers_leave_the_warnings_to_the_parent(tmp_path):
    # a real LocalCluster of one worker (about 3 s): its tasks warn; only the control warning
    # reaches the terminal (which shows that the worker's warnings would)
    pytest.importorskip("distributed")
    r = _run_ok(tmp_path / "cluster.py", CLUSTER, 120)
    assert "control (in a worker)" in r.stderr, r.stderr
    assert "OutOfRangeWarning" not in r.stderr and "KernelCacheWarning" not in r.stderr, r.stderr


REMOTE = """
import warnings
import distributed
from raytrace.executors import dask_client
from raytrace.kernels.jit import KernelCacheWarning
from raytrace.materials import model_glass


def glass():
    return float(model_glass(1.6, 40.0).index(1550.0))


def warn_on(client, text, category, worker=None):
    kw = {} if worker is None else {"workers": [worker]}
    client.submit(warnings.warn, text, category, pure=False, **kw).result()


if __name__ == "__main__":
    # a cluster that dask_client does not start (no preload): a remote one, as tcp://HOST:PORT
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    raw = distributed.Client(cluster)
    try:
        warn_on(raw, "no cache (before)", KernelCacheWarning)
        client, close = dask_client(cluster.scheduler_address)
        try:
            client.submit(glass, pure=False).result()
            warn_on(client, "no cache (connected)", KernelCacheWarning)
            warn_on(client, "control (connected)", UserWarning)
            # a worker that joins while the client is connected is quiet too
            first = set(client.scheduler_info()["workers"])
            cluster.scale(2)
            client.wait_for_workers(2)
            (late,) = set(client.scheduler_info()["workers"]) - first
            warn_on(client, "no cache (late worker)", KernelCacheWarning, late)
            warn_on(client, "control (late worker)", UserWarning, late)
        finally:
            close()
        # the client gone, its plugin is torn down: the workers warn as before
        warn_on(raw, "no cache (after)", KernelCacheWarning)
    finally:
        raw.close()
        cluster.close()
    print("ok")
"""


def test_remote_cluster_workers_leave_the_warnings_to_the_parent_while_connected(tmp_path):
    # a remote scheduler's workers got no preload: the warnings the local workers leave to the
    # parent repeated at every evaluation on each of them. dask_client("tcp://...") registers a
    # worker plugin (raytrace.executors.quiet_remote_workers) that ignores them on every worker,
    # also one that joins later, and that its close() removes again (about 5 s)
    pytest.importorskip("distributed")
    r = _run_ok(tmp_path / "remote.py", REMOTE, 180)
    err = r.stderr
    assert "no cache (before)" in err and "no cache (after)" in err, err  # the plugin's edges
    assert "control (connected)" in err and "control (late worker)" in err, err
    assert "no cache (connected)" not in err and "no cache (late worker)" not in err, err
    assert "OutOfRangeWarning" not in err, err


def test_a_dask_run_quiets_the_event_loop_it_runs_on_too():
    # a Ctrl-C inside distributed.utils.sync once printed "tornado.application - ERROR - Exception
    # in callback ..." and its traceback beside the command's one line: Dask's own config sets
    # tornado.application to ERROR, and only the distributed loggers were raised
    pytest.importorskip("distributed")
    code = """
import logging
import distributed
from raytrace.executors import quiet_dask_logs
quiet_dask_logs(logging.CRITICAL)
logging.getLogger("tornado.application").error("Exception in callback")
logging.getLogger("asyncio").error("Task exception was never retrieved")
logging.getLogger("distributed.utils").error("distributed")
print("done")
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout == "done\n", r.stderr
    assert r.stderr == ""
