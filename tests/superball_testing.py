"""Helpers shared by the Python end-to-end tests: where the binary is, the environment
mpirun needs, and the processes below mpirun."""
import os
import unittest

SOURCE = os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def superball_binary():
    """The binary under test: $SUPERBALL (set by ctest), else a build of this repository."""
    path = os.environ.get("SUPERBALL")
    if path:
        return os.path.abspath(path)
    for build in ("build/release", "build/native"):
        candidate = os.path.join(SOURCE, build, "src", "superball")
        if os.access(candidate, os.X_OK):
            return candidate
    raise unittest.SkipTest("no superball binary: set SUPERBALL")


def mpi_env():
    """The environment for mpirun: Open MPI refuses to run as root unless told."""
    env = dict(os.environ)
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def descendants(pid):
    """Every process below `pid`: Open MPI puts its ranks in process groups of their own,
    so signalling mpirun's group does not reach them."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found
