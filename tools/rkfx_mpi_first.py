"""Load the mpich wheel's libmpi before the first dolfinx, petsc4py or slepc4py import.

``make env`` copies this module into the environment's site-packages as ``_rkfx_mpi_first.py``
beside ``rkfx-mpi.pth``, whose one line imports it when the interpreter starts. The extension
modules of dolfinx and petsc4py need ``libmpi.so.12``, which the mpich wheel puts in
``<venv>/lib``, outside the dynamic loader's search path; only ``import mpi4py.MPI`` (or
``import dolfinx_solver``) used to load it, so plain ``import dolfinx`` failed.

Loading libmpi costs about 50 ms, so it is not done at start-up: a finder on ``sys.meta_path``
waits for the first import of one of those packages, loads the same file mpi4py would load
(with ``RTLD_GLOBAL``, so the extensions resolve to it and the process holds one MPI), and
steps aside. Start-up itself pays for importing this module only (no numpy, no mpi4py).
"""
import os
import sys

#: Top-level packages whose extension modules link libmpi.so.12.
NEEDS_MPI = frozenset({"dolfinx", "petsc4py", "slepc4py"})


class MpiFirst:
    """Meta-path finder that finds nothing; it only loads libmpi before the first import that needs it."""

    @classmethod
    def find_spec(cls, name, path=None, target=None):  # noqa: ARG003 - the finder protocol
        """Load libmpi if ``name`` needs it, then let the usual finders import ``name``."""
        if name.partition(".")[0] in NEEDS_MPI:
            cls.uninstall()
            load_libmpi()
        return None

    @classmethod
    def uninstall(cls) -> None:
        """Take the finder off ``sys.meta_path``; it is needed once per process."""
        if cls in sys.meta_path:
            sys.meta_path.remove(cls)


def load_libmpi() -> None:
    """dlopen ``<prefix>/lib/libmpi.so.12`` globally, where the mpich wheel installs it."""
    lib = os.path.join(sys.prefix, "lib", "libmpi.so.12")
    # MPI4PY_LIBMPI picks another MPI for mpi4py; loading ours too would put two in the process.
    if "MPI4PY_LIBMPI" in os.environ or not os.path.isfile(lib):
        return
    import _ctypes  # noqa: PLC0415 - the C core of ctypes, much cheaper to import than ctypes

    _ctypes.dlopen(lib, os.RTLD_GLOBAL | os.RTLD_LAZY)


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once)."""
    if MpiFirst not in sys.meta_path:
        sys.meta_path.insert(0, MpiFirst)


install()
