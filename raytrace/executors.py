"""Where long work runs: a Dask cluster for the work that scales out (the tolerancing Monte Carlo,
:mod:`distortion.tolerance.montecarlo`; the global search's starts,
:mod:`raytrace.optimize.global_search`). Dask (``distributed``) is the optional ``dask`` extra;
it is imported only when a cluster is asked for.
"""

from __future__ import annotations

from collections.abc import Callable

from .errors import OrthoscopeError


def dask_client(executor) -> tuple[object, Callable[[], None] | None]:
    """``(client, close)`` for an executor spec.

    Parameters
    ----------
    executor : str or distributed.Client
        ``"local"`` or ``"local:N"``: a Dask ``LocalCluster`` on this machine (N worker
        processes, one thread each; default: Dask's choice); ``"tcp://HOST:PORT"``: a running
        scheduler; a ``distributed.Client``: used as it is.

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
    try:
        import distributed
    except ImportError:
        raise OrthoscopeError(
            "Dask is not installed; install the extra: pip install 'orthoscope[dask]'"
        ) from None
    if isinstance(executor, distributed.Client):
        return executor, None
    if isinstance(executor, str) and executor.startswith("local"):
        n = None
        if ":" in executor:
            try:
                n = int(executor.split(":", 1)[1])
            except ValueError:
                raise OrthoscopeError(
                    f"--dask {executor!r}: write local or local:N (N workers)"
                ) from None
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address=None)  # fmt: skip
        client = distributed.Client(cluster)

        def close():
            client.close()
            cluster.close()

        return client, close
    if isinstance(executor, str) and "://" in executor:
        try:
            client = distributed.Client(executor, timeout="20s")
        except OSError as e:
            raise OrthoscopeError(f"cannot reach the Dask scheduler {executor}: {e}") from None
        return client, client.close
    raise OrthoscopeError(
        f"executor {executor!r} is not known; use None/'local' (this machine), 'local[:N]' "
        "(a Dask LocalCluster), 'tcp://HOST:PORT' or a distributed.Client"
    )
