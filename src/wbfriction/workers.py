"""Worker processes that end with the process that started them, whatever ends it.

:func:`process_pool` is the one way the package starts processes. Its workers

* end when their parent ends, SIGKILL included: on Linux the kernel sends them SIGKILL when the
  parent dies (``prctl(PR_SET_PDEATHSIG)``); elsewhere a thread in each worker polls its parent
  (:func:`end_with_parent`). A worker whose parent died before it could arrange this leaves at once.
  Multiprocessing's resource tracker, which ends when the last process holding its pipe has
  ended, then ends too;
* leave the signals that end a command to the parent: a worker ignores SIGINT (the terminal
  sends Ctrl-C to every process of the job; the parent decides) and dies quietly of SIGTERM or
  SIGHUP, and these signals are held back while a worker starts, so that it never prints a
  traceback of its own;
* are killed at once when the ``with`` block is left by an exception (an interruption, an error,
  a generator closed early) instead of being waited for: only a normal exit waits for the work
  submitted. The pool's own thread then fails the futures left with ``BrokenProcessPool``, closes
  the pipe that fed the workers and ends; nothing cancels a future behind its back (see
  :meth:`_Pool.map`), so that the process ends at once, without a thread's traceback.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager
from itertools import islice
from multiprocessing import resource_tracker
from typing import Any, Literal, ParamSpec, TypeVar

StartMethod = Literal["spawn", "fork"]
"""How workers start: ``spawn`` (a fresh interpreter: safe beside threads) or ``fork`` (a copy of
the parent: fast, shares its memory; only from a parent without threads that hold locks)."""
Mechanism = Literal["prctl", "poll"]
"""How a worker learns that its parent ended: the kernel's parent-death signal (Linux) or a thread
polling the parent's process id (any POSIX system, within :data:`POLL_PERIOD`)."""

POLL_PERIOD = 0.2
"""Seconds between two looks at the parent's process id (:func:`end_with_parent` by ``poll``)."""
PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal a process receives when its parent thread ends (linux/prctl.h)."""
_HELD = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
"""The signals that end a command: held back while a worker starts (it inherits the mask)."""

P = ParamSpec("P")
T = TypeVar("T")


def end_with_parent(parent: int, mechanism: Mechanism | None = None) -> None:
    """Make the calling process end when process ``parent`` (its parent) ends.

    Args:
        parent: the process id of the caller's parent, read in the parent before the caller
            started (read here, it could already be the process that adopted an orphan).
        mechanism: ``prctl`` (SIGKILL from the kernel at once; Linux only), ``poll`` (a daemon
            thread that calls ``os._exit(1)`` within :data:`POLL_PERIOD` seconds), or None: ``prctl``
            on Linux, else ``poll``.

    The parent-death signal comes when the *thread* that started the caller ends: start
    workers from a thread that outlives them (the main thread). If ``parent`` has already
    ended, the caller leaves at once (``os._exit(1)``).

    Raises:
        OSError: ``prctl`` refused.
    """
    mechanism = mechanism or ("prctl" if sys.platform.startswith("linux") else "poll")
    if mechanism == "prctl":
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(PR_SET_PDEATHSIG, ctypes.c_ulong(signal.SIGKILL), ctypes.c_ulong(0), ctypes.c_ulong(0),
                      ctypes.c_ulong(0)) != 0:
            errno = ctypes.get_errno()
            raise OSError(errno, f"prctl(PR_SET_PDEATHSIG): {os.strerror(errno)}")
    else:
        threading.Thread(target=_poll_parent, args=(parent,), name="end-with-parent", daemon=True).start()
    if os.getppid() != parent:  # the parent ended before the signal was armed
        os._exit(1)


def _poll_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(POLL_PERIOD)
    os._exit(1)


def _start_worker(parent: int, job: bytes) -> None:
    """A worker's first act: tied to its parent, the command-ending signals left to the parent, then
    the caller's initializer (unpickled only now: its imports may take seconds)."""
    end_with_parent(parent)
    _leave_signals_to_parent()
    initializer, initargs = pickle.loads(job)
    if initializer is not None:
        initializer(*initargs)


def _leave_signals_to_parent() -> None:
    """In a worker's main thread: SIGINT ignored, SIGTERM and SIGHUP fatal without a word, then these
    signals let through (they were held back while the worker started)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for sig in _HELD - {signal.SIGINT}:
        signal.signal(sig, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _HELD)


M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
"""``mallopt`` parameters (glibc's malloc.h)."""
HEAP_THRESHOLD = 32 << 20
"""Bytes below which glibc's malloc takes blocks from the heap: the ceiling its adaptive mmap threshold grows to
on a 64-bit system (``DEFAULT_MMAP_THRESHOLD_MAX``); the heap is trimmed above twice this."""


def heap_for_arrays() -> bool:
    """Undo, in this process, what Dask's ``MALLOC_TRIM_THRESHOLD_=65536`` (set by every ``dask worker``'s nanny)
    does to glibc's malloc: that variable turns off the adaptive mmap threshold, so every NumPy array above 128 KiB
    is mapped and unmapped afresh, its pages faulted in each time (a log's task 1.5-2x as long as in a plain
    process, issue 25). Sets the thresholds the adaptive rule would reach (:data:`HEAP_THRESHOLD`). True if it did;
    False without the variable or glibc (nothing to undo)."""
    if "MALLOC_TRIM_THRESHOLD_" not in os.environ:
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, HEAP_THRESHOLD)) and bool(mallopt(M_TRIM_THRESHOLD, 2 * HEAP_THRESHOLD))


def dask_setup(worker: object) -> None:
    """Dask's preload hook (``distributed.worker.preload`` naming this module, :data:`DASK_PRELOAD`),
    run in each worker process of a cluster started by :func:`started_held` before it takes a task:
    the worker leaves the command-ending signals to the command, as those of :func:`process_pool`
    do (a Ctrl-C, which the terminal sends to every process of the job, does not make each Dask
    worker print a ``KeyboardInterrupt`` traceback)."""
    _leave_signals_to_parent()
    sys.unraisablehook = _quiet_closed_loop_clients(sys.unraisablehook)


def _quiet_closed_loop_clients(hook: Callable[[Any], object]) -> Callable[[Any], object]:
    """``hook`` less the one finalizer failure an interrupted Dask worker meets: a task still running
    when its worker closed (a thread cannot be stopped) asks for the worker's client
    (``distributed.get_client``) after the worker's event loop has closed; that client's finalizer,
    run as the process ends, then fails with ``RuntimeError: IOLoop is closed`` and would print a
    traceback (the client has nothing left to close: its loop is gone)."""
    from distributed import Client

    def quiet(unraisable: Any) -> None:
        if not (getattr(unraisable.object, "__qualname__", None) == Client.__del__.__qualname__
                and isinstance(unraisable.exc_value, RuntimeError) and "IOLoop is closed" in str(unraisable.exc_value)):
            hook(unraisable)

    return quiet


DASK_PRELOAD = __name__
"""The module a Dask cluster's ``distributed.worker.preload`` names so that its workers run
:func:`dask_setup`."""


def started_held(start: Callable[[], T], close: Callable[[T], object]) -> T:
    """``start()`` with the command-ending signals held back (a thread it starts, and a process that
    thread starts, at once or later, starts with them held: a Dask cluster's event loop and the
    worker processes it spawns); if one arrived meanwhile, ``close(started)`` and then the signal is
    raised. Multiprocessing's resource tracker is started before: started inside, it would let the
    signals through again in this thread (``resource_tracker.ensure_running`` unblocks them)."""
    resource_tracker.ensure_running()
    started: list[T] = []
    try:
        with _signals_held():
            started.append(start())
    except BaseException:
        for made in started:
            close(made)
        raise
    return started[0]


@contextmanager
def _signals_held() -> Iterator[None]:
    """The command-ending signals held back: blocked (a process started here inherits the mask)
    and, in the main thread, their Python handlers deferred to the end of the block (a handler
    that raised between the start of a spawned worker and the data sent to it would leave the
    worker to die with a traceback)."""
    caught: list[int] = []
    deferred = {}
    mask = None
    try:
        if threading.current_thread() is threading.main_thread():
            for sig in _HELD:
                if signal.getsignal(sig) is not None:  # None: a handler set outside Python, left alone
                    deferred[sig] = signal.signal(sig, lambda signum, frame: caught.append(signum))
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
        yield
    finally:
        if mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        for sig, handler in deferred.items():
            signal.signal(sig, handler)
        for signum in caught:  # delivered again, to the handler restored
            signal.raise_signal(signum)


class _Pool(ProcessPoolExecutor):
    """A pool whose processes start (at a submission) with the command-ending signals held back, and
    whose :meth:`map` cancels no future."""

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        with _signals_held():
            return super().submit(fn, *args, **kwargs)

    def map(self, fn: Callable[..., T], *iterables: Iterable[Any], timeout: float | None = None,
            chunksize: int = 1) -> Iterator[T]:
        """``fn`` over the iterables, as :meth:`concurrent.futures.Executor.map`: every task submitted at
        once (``chunksize`` calls to a task), the results in order, :class:`TimeoutError` if they are not
        all there ``timeout`` seconds after the call; except that an iterator left early cancels
        nothing: the tasks not started run when the ``with`` block of :func:`process_pool` ends
        normally, and fail with the workers killed when it ends by an exception.

        Why: the standard iterator, left by an exception, cancels the futures not started; when the
        block's exit then kills the workers, Python 3.11's pool thread, failing the futures left,
        raises ``InvalidStateError`` on a cancelled one (CPython gh-107219, mended in 3.12), prints
        its traceback and dies before it closes the pipe that fed the workers; a task larger than
        the pipe's buffer keeps the feeding thread blocked on it, and the process's exit waits for
        that thread forever (issue 37).

        Raises:
            ValueError: ``chunksize`` below 1.
        """
        if chunksize < 1:
            raise ValueError(f"chunksize must be >= 1, not {chunksize}")
        end = None if timeout is None else time.monotonic() + timeout
        calls = zip(*iterables)
        chunks = iter(lambda: list(islice(calls, chunksize)), [])
        futures = deque(self.submit(_call_each, fn, chunk) for chunk in chunks)
        return _in_order(futures, end)


def _call_each(fn: Callable[..., T], chunk: list[tuple]) -> list[T]:
    """A task of :meth:`_Pool.map`: ``fn`` on each tuple of arguments of ``chunk``."""
    return [fn(*args) for args in chunk]


def _in_order(futures: deque[Future[list[T]]], end: float | None) -> Iterator[T]:
    """The results of the tasks of :meth:`_Pool.map`, in order (popped: no reference kept to a
    result given); :class:`TimeoutError` at monotonic time ``end``."""
    while futures:
        yield from futures.popleft().result(None if end is None else end - time.monotonic())


@contextmanager
def process_pool(workers: int, context: StartMethod, initializer: Callable[..., object] | None = None,
                 initargs: tuple = ()) -> Iterator[ProcessPoolExecutor]:
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes that end with
    this one (see the module's description).

    Args:
        workers: processes (>= 1).
        context: how they start (:data:`StartMethod`).
        initializer, initargs: called as ``initializer(*initargs)`` in each worker once it is
            tied to this process; both must pickle.

    Leaving the block normally waits for the submitted work; leaving it by an exception kills
    the workers (no wait): the futures left end cancelled or failed (``BrokenProcessPool``).
    Do not cancel a future of the pool yourself (:meth:`_Pool.map` says why).
    """
    before = set(multiprocessing.active_children())
    job = pickle.dumps((initializer, initargs))
    pool = None
    try:
        with _signals_held():  # a pool half made (its queues, its resource tracker) would not be undone
            pool = _Pool(workers, mp_context=multiprocessing.get_context(context), initializer=_start_worker,
                         initargs=(os.getpid(), job))
        yield pool
    except BaseException:
        with _signals_held():  # a second Ctrl-C waits until the workers are gone
            mine = set(multiprocessing.active_children()) - before
            for process in mine:
                process.kill()
            for process in mine:
                process.join(5.0)
            if pool is not None:  # its thread sees the workers gone, fails the futures left and ends
                pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
