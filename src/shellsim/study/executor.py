"""Running a study's jobs through dask.distributed: a local cluster (one single-threaded
worker process per core) or an existing scheduler. Rows come back as jobs finish; a job
that raises becomes a failed row, not the end of the study.

Two known pitfalls are avoided: the numba cache is compiled in the client before any job
is submitted (concurrent compiles into one cache have crashed dask workers), and meshes
are built with gmsh initialised for use outside the main thread (dask runs tasks in
worker threads; see :mod:`shellsim.geometry.session`).
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

from ..errors import StudyError
from ..threads import usable_cpus
from .jobs import Job, failed_row, run_job

WARM_UP_DECK = """
[meta]
title = "numba cache warm-up"
[geometry]
builder = "rectangle"
length = 1.0
width = 1.0
[mesh]
divisions = { length = 1, width = 1 }
[material]
model = "neo_hookean"
C1 = 1.0
density = 1.0
[section]
thickness = 0.1
[solver]
end_time = 1e-3
[output]
fields = ["displacement", "cauchy_stress", "pressure_band"]
[[contact]]
type = "shells"
name = "fold"
[[contact]]
type = "rigid_tool"
name = "floor"
shape = "plane"
point = [0.0, 0.0, -1.0]
normal = [0.0, 0.0, 1.0]
"""


#: The static solve's kernels (element and follower-pressure tangents) on the same scene.
#: The everyday scene, loads and no contact: its own time loop (a model's type, and so its
#: compiled time loop, follows the load kinds it has: :data:`shellsim.loads.Loads`).
WARM_UP_EVERYDAY = WARM_UP_DECK[:WARM_UP_DECK.index("[[contact]]")] + """[[load]]
type = "pressure"
set = "all"
value = 1e-3
"""
WARM_UP_STATIC = WARM_UP_EVERYDAY.replace("end_time = 1e-3", 'method = "static"\nend_time = 1e-3')


def warm_numba_cache() -> None:
    """Compile the kernels of the explicit and static runs, here, once, so workers mostly
    only load the cache: the everyday scene's and every contact kind's (a mix of kinds not
    warmed compiles its own time loop where it first runs)."""
    from ..deck import parse_deck
    from ..execute import run_scene

    for text in (WARM_UP_DECK, WARM_UP_EVERYDAY, WARM_UP_STATIC):
        with tempfile.TemporaryDirectory() as folder:
            deck = Path(folder) / "warm_up.toml"
            deck.write_text(text)
            run_scene(parse_deck(text), deck, Path(folder))


def prepare_workers(client, local: bool) -> None:
    """Warm the numba cache in the client (local cluster: the workers share it), then run
    the warm-up on every worker so the first job's wall time holds no loading of kernels."""
    if local:
        warm_numba_cache()
    client.run(warm_numba_cache)


#: Seconds to wait for a scheduler to answer before saying it did not.
CONNECT_TIMEOUT = 5.0


def _ask_identity(address: str, timeout: float) -> None:
    """Ask what listens at ``address``, waiting ``timeout`` seconds for the connection and
    twice that for the answer; raises StudyError unless a dask scheduler answers (a port that
    takes the connection but says nothing, or something else, kept dask's Client waiting
    for ever or ended in its MemoryError). OSError when nothing can be reached there."""
    import asyncio

    from distributed.comm import connect

    async def identity():
        # OSError within ``timeout`` when nothing takes the connection; a port that takes it
        # and stays silent holds connect's own handshake, which the outer wait ends
        comm = await connect(address, timeout=timeout)
        try:
            await comm.write({"op": "identity"})
            return await comm.read()
        finally:
            comm.abort()

    try:
        answer = asyncio.run(asyncio.wait_for(identity(), 2.0 * timeout))
    except TimeoutError:  # the connection taken, no word back (an OSError too, so first)
        answer = None
    except (OSError, ValueError):
        raise
    except Exception as error:  # what a stranger's bytes make of dask's framing
        answer = f"bytes dask cannot read ({type(error).__name__}: {str(error)[:80]})"
    if not (isinstance(answer, dict) and answer.get("type") == "Scheduler"):
        said = (answer if isinstance(answer, str) else "nothing" if answer is None else
                f"as a dask {answer.get('type', 'something')}")
        raise StudyError(f"'{address}' took the connection but answered {said} within {2 * timeout:g} s, not as a "
                         "dask scheduler; give the address a dask scheduler prints (tcp://HOST:8786 by default)")


def open_client(scheduler: str | None, workers: int | None = None, timeout: float = CONNECT_TIMEOUT):
    """A dask client on ``scheduler`` (tcp://host:port), or on a new local cluster of
    ``workers`` single-threaded processes (default: one per CPU this process may use). Raises StudyError when
    the scheduler does not answer within ``timeout`` seconds, or something else answers.

    On the local cluster a job whose worker dies is not given to another worker (dask's
    default tries three more, so one crashing job took four workers down): it becomes a
    failed row naming the job."""
    import dask
    from dask.distributed import Client

    if scheduler:
        try:
            _ask_identity(scheduler, timeout)
            return Client(scheduler, timeout=timeout)
        except (OSError, ValueError) as error:
            raise StudyError(f"the dask scheduler at '{scheduler}' did not answer within {timeout:g} s "
                             f"({type(error).__name__}: {error}); is it running, and is the address "
                             "tcp://HOST:PORT?") from None
    # the client owns this cluster and shuts it down when closed
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        return Client(n_workers=workers or usable_cpus(), threads_per_worker=1, processes=True,
                      dashboard_address=None)


def run_jobs(jobs: list[Job], client, on_row: Callable[[dict], None], threads: int | None = None,
             work: Callable[[Job, int | None], dict] | None = None) -> None:
    """Submit every job to ``client`` and call ``on_row`` with each row as it finishes;
    ``threads``: the kernels' threads in each job (None: the worker's default); ``work``
    runs a job in a worker (default :func:`run_job_on_threads`)."""
    from dask.distributed import KilledWorker, as_completed

    futures = {client.submit(work or run_job_on_threads, job, threads, key=f"shellsim-{i}-{job.key}", pure=False): job
               for i, job in enumerate(jobs)}
    for future in as_completed(futures):
        job = futures[future]
        if future.status == "error":
            error = future.exception()
            if isinstance(error, KilledWorker):
                error = StudyError(f"the worker process running this job ({job.deck}, variant '{job.label}') died: "
                                   f"a crash in compiled code or too little memory ({error})")
            on_row(failed_row(job, error))
        else:
            on_row(future.result())


def run_job_on_threads(job: Job, threads: int | None) -> dict:
    """:func:`run_job` with the kernels on ``threads`` threads (numba's setting is per
    calling thread, so it is made in the thread that runs the job)."""
    if threads is not None:
        import numba

        numba.set_num_threads(threads)
    return run_job(job)


def rows_in_order(jobs: list[Job], rows: list[dict]) -> Iterator[dict]:
    """``rows`` in the study's order of jobs (they arrive in the order jobs finish)."""
    by_key = {(r["family"], r["variant"]): r for r in rows}
    for job in jobs:
        if (job.family, job.label) in by_key:
            yield by_key[(job.family, job.label)]
