"""The RKPM u-p options the consolidation cases share: how the displacement conditions are
imposed and which linear solver steps the system (``rkfx.models.poroelasticity.solve_biot``).

``bc_method=nitsche`` imposes the displacements weakly, which the field split's multigrid on the
displacement block needs; ``solver=auto`` factorizes by MUMPS and takes the field split above
``rkfx.models.poroelasticity.U_P_AUTO_DIRECT_MAX_DOFS`` unknowns when that is possible.
"""
from rkfx.assembly.boundary import BC_METHODS
from rkfx.cases import _preflight
from rkfx.cases._cli import Param
from rkfx.errors import InputError
from rkfx.models.poroelasticity import SOLVER_CHOICES

PARAMS = {
    "bc_method": Param("transformation", "RKPM displacement conditions: transformation (collocated) or nitsche"),
    "solver": Param("auto", "RKPM linear solver: auto (MUMPS, or the field split above 300k unknowns with nitsche), "
                            "mumps, or fieldsplit (GMRES with a Schur split; needs nitsche)"),
}


def check(bc_method: str, solver: str) -> None:
    """Raise InputError for an unknown choice or a field split without Nitsche's conditions."""
    _preflight.known([bc_method], BC_METHODS, "bc_method")
    _preflight.known([solver], SOLVER_CHOICES, "RKPM linear solver")
    if solver == "fieldsplit" and bc_method != "nitsche":
        raise InputError("solver=fieldsplit needs bc_method=nitsche (multigrid on the displacements)")
