"""Where long work runs: a Dask cluster for the work that scales out (the tolerancing Monte Carlo,
:mod:`distortion.tolerance.montecarlo`; the global search's starts,
:mod:`raytrace.optimize.global_search`). Dask (``distributed``) is the optional ``dask`` extra;
it is imported only when a cluster is asked for.
"""

from __future__ import annotations

import os
import re
import signal
import threading
from collections.abc import Callable

from .errors import OrthoscopeError

#: the executor specs a user can write: ``local``, ``local:N`` (N >= 1) or ``tcp://HOST:PORT``
#: (HOST a name, an IPv4 address or a bracketed IPv6 address)
_SPEC = re.compile(r"local(?::(?P<n>\d+))?|tcp://(?:\[[0-9A-Fa-f:.]+\]|[^\s:/\[\]]+):(?P<port>\d+)")

#: at most this many LocalCluster worker processes per CPU (more is a typo, not a plan)
MAX_LOCAL_PER_CPU = 4


def check_executor(text: str) -> str:
    """``text`` if it is an executor spec :func:`dask_client` takes; else OrthoscopeError.

    Checked before any work: ``local``, ``local:N`` with 1 <= N <= MAX_LOCAL_PER_CPU x the
    CPUs worker processes, or ``tcp://HOST:PORT`` with a port from 1 to 65535.
    """
    m = _SPEC.fullmatch(text) if isinstance(text, str) else None
    if m is None or (m["n"] is not None and int(m["n"]) < 1):
        raise OrthoscopeError(
            f"--dask {text!r}: give local (a LocalCluster of one worker per CPU), local:N (N >= 1 "
            "workers) or tcp://HOST:PORT (a running scheduler)"
        )
    if m["port"] is not None and not 1 <= int(m["port"]) <= 65535:
        raise OrthoscopeError(f"--dask {text!r}: the port must be 1 to 65535")
    cpus = os.cpu_count() or 1
    if m["n"] is not None and int(m["n"]) > MAX_LOCAL_PER_CPU * cpus:
        raise OrthoscopeError(
            f"--dask {text!r}: {int(m['n'])} worker processes on a machine with {cpus} CPU(s); "
            f"use at most {MAX_LOCAL_PER_CPU * cpus} (a tcp:// scheduler for a larger cluster)"
        )
    return text


#: The warnings a worker process leaves to the parent, as (module, class name) (imported only
#: when a worker starts: the kernels' module imports numba). The parent says each once, in one
#: line; a worker would repeat it for every evaluation, in raw multi-line form on the parent's
#: terminal. :func:`ignore_worker_warnings` applies the list in the workers of the global
#: search's process pool (``raytrace.optimize.global_search._init_worker``) and of a Dask
#: LocalCluster (:func:`dask_setup`).
WORKER_QUIET_WARNINGS = (
    # a glass evaluated outside its catalog data range: the parent warns when it evaluates the
    # result (the best design of a global search, the nominal lens of a Monte Carlo) at the
    # same wavelengths, once (with --strict it fails there)
    ("raytrace.materials", "OutOfRangeWarning"),
    # no writable numba kernel cache: the parent has said so in one line
    ("raytrace.kernels.jit", "KernelCacheWarning"),
)


def _quiet_categories() -> list[type[Warning]]:
    """The warning classes :data:`WORKER_QUIET_WARNINGS` names (their modules imported)."""
    import importlib

    return [getattr(importlib.import_module(m), name) for m, name in WORKER_QUIET_WARNINGS]


def ignore_worker_warnings() -> None:
    """In a worker process: ignore the warning categories of :data:`WORKER_QUIET_WARNINGS`."""
    import warnings

    for category in _quiet_categories():
        warnings.simplefilter("ignore", category)


#: on a remote Dask worker: the names of the :class:`QuietWarningsPlugin` instances set up
#: there, and the warning filters they added (removed when the last one is torn down)
_QUIET_PLUGINS: set[str] = set()
_QUIET_FILTERS: list[tuple] = []


def _quiet_worker_warnings(name: str) -> None:
    """:func:`ignore_worker_warnings` for the plugin ``name`` (a remote worker; the filters
    already there are left as they are, and none is added twice)."""
    import warnings

    if not _QUIET_PLUGINS:
        for category in _quiet_categories():
            entry = ("ignore", None, category, None, 0)  # as simplefilter adds it
            if entry not in warnings.filters:
                warnings.simplefilter("ignore", category)
                _QUIET_FILTERS.append(entry)
    _QUIET_PLUGINS.add(name)


def _unquiet_worker_warnings(name: str) -> None:
    """Undo :func:`_quiet_worker_warnings` of the plugin ``name``: once the last such plugin
    is gone, the filters it added are removed (the worker warns as it did before)."""
    import warnings

    _QUIET_PLUGINS.discard(name)
    if _QUIET_PLUGINS:
        return
    while _QUIET_FILTERS:
        entry = _QUIET_FILTERS.pop()
        if entry in warnings.filters:
            warnings.filters.remove(entry)
    getattr(warnings, "_filters_mutated", lambda: None)()  # no cached verdict outlives them


def _quiet_warnings_plugin_class():
    """The class :data:`QuietWarningsPlugin`, made on first use (it subclasses
    ``distributed.WorkerPlugin``, and this module imports Dask only when a cluster is asked
    for)."""
    from distributed import WorkerPlugin

    class QuietWarningsPlugin(WorkerPlugin):
        """On every worker of a remote cluster (one that :func:`dask_client` did not start, so
        no preload): the warnings of :data:`WORKER_QUIET_WARNINGS` are ignored while this
        client is connected, as the workers of a LocalCluster and of the process pool ignore
        them; its teardown (the client's close) puts the worker's warnings back. SIGINT and
        the worker's logging are left alone: the worker belongs to whoever started it."""

        def __init__(self, name: str) -> None:
            self.name = name

        def setup(self, worker) -> None:
            _quiet_worker_warnings(self.name)

        def teardown(self, worker) -> None:
            _unquiet_worker_warnings(self.name)

    QuietWarningsPlugin.__module__ = __name__
    QuietWarningsPlugin.__qualname__ = "QuietWarningsPlugin"
    return QuietWarningsPlugin


def __getattr__(name: str):
    # QuietWarningsPlugin: made when first asked for (by dask_client, or by pickle on a worker
    # unpickling the plugin), then a plain module attribute
    if name == "QuietWarningsPlugin":
        cls = globals()[name] = _quiet_warnings_plugin_class()
        return cls
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def quiet_remote_workers(client) -> Callable[[], None]:
    """Register a :class:`QuietWarningsPlugin` on the cluster of ``client`` (its workers now
    and those that join later); returns the function that unregisters it. Best effort: a
    cluster that refuses the plugin (its workers cannot import raytrace: the tasks would fail
    there anyway, with their own error) runs without it."""
    import uuid

    name = f"orthoscope-quiet-warnings-{uuid.uuid4().hex}"
    try:
        client.register_plugin(__getattr__("QuietWarningsPlugin")(name), name=name)
    except Exception:  # the warnings are noise, not a reason to fail
        return lambda: None

    def undo() -> None:
        if client.status != "running":  # scheduler lost: it would wait for it to come back
            return
        try:
            client.unregister_worker_plugin(name)
        except Exception:  # a cluster already gone has no plugin left to remove
            pass

    return undo


def dask_setup(worker) -> None:
    """Dask preload hook, run in each worker process that :func:`dask_client` starts: Ctrl-C in
    the terminal reaches the whole process group, and the workers leave it to this process
    (which stops the work and keeps what finished) instead of dying with tracebacks; the
    workers, which share this process's terminal, log nothing below CRITICAL (a task's error
    reaches this process as its exception; what they would log is the noise of a stopped run:
    cancelled tasks, heartbeats to a scheduler already closed); and they leave the warnings of
    :data:`WORKER_QUIET_WARNINGS` to this process (:func:`ignore_worker_warnings`, as the local
    process pool's workers do)."""
    import logging

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    quiet_dask_logs(logging.CRITICAL)
    ignore_worker_warnings()


#: the loggers a Dask run writes to: its own, and those of the event loop it runs on (an
#: exception in one of its callbacks, e.g. a Ctrl-C that lands inside ``distributed.utils.sync``,
#: is logged with its traceback on ``tornado.application``, which Dask's own config sets to ERROR)
DASK_LOGGERS = ("distributed", "tornado", "asyncio")


def quiet_dask_logs(level: int) -> None:
    """Raise the loggers of a Dask run (:data:`DASK_LOGGERS` and below, as the import of
    ``distributed`` configured them) to at least ``level`` (a :mod:`logging` level)."""
    import logging

    names = [n for n in logging.root.manager.loggerDict if n.split(".")[0] in DASK_LOGGERS]
    for name in {*DASK_LOGGERS, *names}:
        log = logging.getLogger(name)
        log.setLevel(max(log.level, level))


def require_dask():
    """The ``distributed`` module; OrthoscopeError (one line, how to install it) when Dask is not
    installed. Cheap: a command checks it before any long work."""
    try:
        import distributed
    except ImportError:
        raise OrthoscopeError(
            "Dask is not installed; install the extra: pip install 'orthoscope[dask]'"
        ) from None
    return distributed


def dask_client(executor) -> tuple[object, Callable[[], None] | None]:
    """``(client, close)`` for an executor spec.

    Parameters
    ----------
    executor : str or distributed.Client
        ``"local"`` or ``"local:N"``: a Dask ``LocalCluster`` on this machine (N >= 1 worker
        processes, one thread each; ``"local"``: one per CPU), whose workers ignore Ctrl-C
        and leave the warnings of :data:`WORKER_QUIET_WARNINGS` to this process
        (:func:`dask_setup`); ``"tcp://HOST:PORT"``: a running scheduler, whose workers ignore
        those warnings while this client is connected (:func:`quiet_remote_workers`; their
        SIGINT and logging are theirs); a ``distributed.Client``: used as it is.

    Returns
    -------
    (client, close)
        The ``distributed.Client`` and the function that shuts down what this call started
        (None for a client given by the caller).

    Raises
    ------
    OrthoscopeError
        Dask is not installed, the spec is malformed, or the scheduler cannot be reached.
    """
    distributed = require_dask()
    if isinstance(executor, distributed.Client):
        return executor, None
    if not isinstance(executor, str):
        raise OrthoscopeError(
            f"executor {executor!r} is not known; use 'local', 'local:N' (a Dask LocalCluster), "
            "'tcp://HOST:PORT' or a distributed.Client"
        )
    check_executor(executor)
    if executor.startswith("local"):
        n = int(executor[6:]) if ":" in executor else None
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address=None,
                                           preload=["raytrace.executors"])  # fmt: skip
        client = distributed.Client(cluster)

        def close():
            client.close()
            cluster.close()

        return client, close
    try:
        client = distributed.Client(executor, timeout="20s")
    except OSError as e:
        raise OrthoscopeError(f"cannot reach the Dask scheduler {executor}: {e}") from None
    unquiet = quiet_remote_workers(client)  # no preload there: the warnings, as a plugin

    def close_remote():
        unquiet()
        client.close()

    return client, close_remote
