"""What a case checks before any work: its documented parameter ranges and whether it fits in memory.

``rkfx.cases._cli.main`` calls :func:`before_work` as soon as the parameters are parsed. A case
module may define

    check(**params)                 raise InputError for a parameter outside its documented range
    memory_need(methods, **params)  a Need: the estimated peak memory of its largest run

Both receive every parameter of the case; neither may allocate much or start the work, so a
refused run costs nothing and writes nothing.
"""
import inspect
import math
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from rkfx.errors import InputError

GB = 1e9
# Resident memory of a case before its first model: Python with numpy, scipy, numba's cached
# kernels and dolfinx loaded. Measured (peak RSS, /usr/bin/time -v) on mandel --quick
# --method rkpm: 0.45 GB for 205 nodes, essentially all of it imports.
BASE_BYTES = 0.5 * GB


@dataclass(frozen=True)
class Need:
    """The estimated peak memory of a case's largest run.

    Attributes:
        bytes: Estimated peak resident memory of one process [bytes], imports included.
        what: The sizes that set it, as given, e.g. ``nx=1000000000``.
        fix: What to change, e.g. ``lower nx or ny``.
    """

    bytes: float
    what: str
    fix: str


# Peak resident memory per node above BASE_BYTES, measured with /usr/bin/time -v on serial runs
# (the figures a case's memory_need scales by its largest model's node count).
# u-p RKPM (mandel --quick --method rkpm, two variants): 1.0 GB at 201 x 21 nodes, 3.8 GB at 401 x 41,
# i.e. 137 kB per node at 4k nodes and 207 kB at 16k: the sparse factorizations fill in, so the
# figure per node grows like (nodes / 4000)^0.3 (an overestimate beyond, where fill grows like log n).
PORO_RKPM_BYTES_PER_NODE = 140e3
PORO_RKPM_FILL_NODES, PORO_RKPM_FILL_EXPONENT = 4000.0, 0.3
# u-p FEM (mandel --quick --method fem, taylor-hood and q1q1): 0.48 GB at 201 x 21 vertices,
# 1.3 GB at 401 x 41, about 67 kB per vertex.
PORO_FEM_BYTES_PER_NODE = 80e3
# Explicit damage dynamics (kalthoff --method rkpm, t_end 1 us): 0.30 GB at 14.5k particles, 0.51 GB
# at 63k, about 4.4 kB per particle; doubled for the full-length histories and the FEM baseline.
DAMAGE_BYTES_PER_NODE = 9e3
# Elastostatics (plate_with_hole, MSCNI and FEM P2 on each level): 0.32 GB up to 991 nodes, 0.38 GB
# up to 3674, about 23 kB per node; RKPM doubled for safety, FEM scaled by degree^2 (dofs per vertex).
ELASTIC_RKPM_BYTES_PER_NODE = 40e3
ELASTIC_FEM_BYTES_PER_NODE = 10e3


def need(per_item: float, count: float, what: str, fix: str) -> Need:
    """A Need of ``BASE_BYTES`` plus ``per_item`` bytes for each of ``count`` nodes (or cells)."""
    return Need(BASE_BYTES + per_item * float(count), what, fix)


def poro_need(methods: Sequence[str], nodes: float, what: str, fix: str) -> Need:
    """The Need of a u-p consolidation case whose largest model has ``nodes`` nodes."""
    fill = max(1.0, float(nodes) / PORO_RKPM_FILL_NODES) ** PORO_RKPM_FILL_EXPONENT
    per = max([PORO_RKPM_BYTES_PER_NODE * fill if "rkpm" in methods else 0.0,
               PORO_FEM_BYTES_PER_NODE if "fem" in methods else 0.0])
    return need(per, nodes, what, fix)


def available_bytes() -> float | None:
    """Memory the machine can give new work [bytes]: ``MemAvailable`` of /proc/meminfo (which
    counts reclaimable caches), else the free pages of ``os.sysconf``; ``None`` if neither is known."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0  # the kernel reports kB
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def refuse_if_too_big(needed: Need, ranks: int = 1, available: float | None = None) -> None:
    """Raise InputError when ``needed`` (on each of ``ranks`` processes of this machine) exceeds
    the available memory; do nothing when the available memory is unknown.

    Raises:
        InputError: ``<what> needs about X GB, this machine has Y GB available; <fix>``.
    """
    avail = available_bytes() if available is None else available
    total = needed.bytes * max(1, ranks)
    if avail is None or total <= avail:
        return
    on = "" if ranks <= 1 else f" ({ranks} ranks, each holding the whole problem)"
    raise InputError(f"{needed.what} needs about {total / GB:.2g} GB{on}, this machine has {avail / GB:.1f} GB "
                     f"available; {needed.fix}")


def module_of(run: Callable) -> Any:
    """The case module that defines ``run``."""
    return sys.modules.get(getattr(run, "__module__", ""), None)


def before_work(run: Callable, params: Mapping[str, Any], methods: Sequence[str], comm=None) -> None:
    """The case's memory estimate against this machine's memory, then its range checks.

    Args:
        run: The case's ``run``; its module supplies ``check`` and ``memory_need`` (both optional).
        params: Every parameter of the case.
        methods: The methods to run, e.g. ``("rkpm", "fem")``.
        comm: MPI communicator or ``None``: under MPI every rank is counted as holding the whole
            problem (conservative for the replicated data of the RKPM models).

    Raises:
        InputError: A parameter outside its range, or a run that cannot fit in memory.
    """
    module = module_of(run)
    estimate = getattr(module, "memory_need", None)
    # The size first: a run too big for the machine is refused for its size, even where a limit
    # derived from it (say the first time step) would trip too. An estimate that cannot be formed
    # from out-of-range values is left to the range checks, which name the culprit.
    try:
        needed = estimate(tuple(methods), **params) if estimate is not None else None
    except (ArithmeticError, TypeError, ValueError):
        needed = None
    if needed is not None:
        refuse_if_too_big(needed, ranks=comm.size if comm is not None else 1)
    check = getattr(module, "check", None)
    if check is not None:
        # A check that names ``methods`` also gets them (e.g. a case without a FEM baseline).
        check(**params, **({"methods": tuple(methods)} if "methods" in inspect.signature(check).parameters else {}))


def support_factor_ok(support_factor: float, low: float = 1.0) -> None:
    """Raise InputError unless ``support_factor`` > ``low`` (the linear RK basis needs at least three
    non-collinear nodes in reach of every point; at 1 nodal spacing or less some points have fewer)."""
    if not (math.isfinite(support_factor) and support_factor > low):
        raise InputError(f"support_factor = {support_factor!r}: use a value > {low:g} (RK support radius / nodal "
                         "spacing; 1.5 is the usual choice)")


def known(values, allowed, what: str) -> None:
    """Raise InputError naming the first of ``values`` that is not one of ``allowed``.

    Raises:
        InputError: ``unknown <what> '<value>'; choose from <allowed>``.
    """
    for v in values:
        if v not in allowed:
            raise InputError(f"unknown {what} {v!r}; choose from {', '.join(allowed)}")
