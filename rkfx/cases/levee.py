"""Seepage-induced levee failure (§6.4.3, Figs 6.10-6.11), stage 1: the initial state, steady
seepage under gravity with the stresses in equilibrium with it, by RKPM beside FEM.

Problem. A sand levee on an impermeable, rigid floor holds a river at water level ``water``
against its upstream slope; water seeps through it and leaves by the downstream slope. The
seed starts its dynamic run "at the critical seepage flow state when material failure is about
to occur", computed by a steady analysis with the water level imposed (after Zienkiewicz et
al. 1999); this case computes that state:

    base                 u = 0, no flow (the flume floor)
    upstream slope       below the water level: p = gamma_w (water - y) and the water's
                         total traction -p n; above it: no flow, traction-free
    crest                no flow, traction-free
    downstream slope     a seepage face (p <= 0, outflow only; ``rkfx.assembly.seepage_face``),
                         traction-free

Equations (6.15)-(6.16) at rest (``rkfx.models.unsaturated_poroelasticity``), the skeleton
carrying its whole weight rho(S_w) g from an unstressed start (``weight="full"``), so that
sigma'' = D eps(u) is the initial effective (Bishop) stress; reached by pseudo-time
continuation (``rkfx.solvers.steady``) from p = 0.

Geometry: the seed shows a sketch only (Fig 6.10), after the model levee of Iseno et al.
(2004) and Mori (2008), whose dimensions were not available here. Assumed, and all
parameters: a trapezoid of height ``height`` = 1 m, crest ``crest`` = 0.5 m wide, both slopes
1 : ``slope_up`` = 1 : ``slope_down`` = 1 : 2 (vertical : horizontal), on a floor 4.5 m long;
the river at ``water`` = 0.8 m (Fig 6.10(b) raises the water to most of the height).
Material (the seed's): E = 1e7 Pa, nu = 0.3, rho_s = 2700, rho_w = 1000 kg/m^3, n = 0.46,
K_s = 1e22, K_w = 1e9 Pa, g = 9.806 m/s^2; van Genuchten (6.82)-(6.83) with S_rw = 0.0842,
n = 2, beta = 0.7 1/m; Drucker-Prager phi = 20 deg, c = 300 Pa. The printed permeability
"5.0e-4 m^2" is read as a hydraulic conductivity of 5e-4 m/s (a clean sand), i.e. a mobility
k = 5e-4 / gamma_w m^2/(Pa s).

Methods, on one gmsh triangulation of size ``h``: RKPM (linear RK, a = 2 h, NSNI with the
variationally consistent correction, equal order u-p, the river's pressure collocated at the
slope's nodes, the seepage face and the traction on the boundary segments' Gauss points) on
its nodes; FEM Taylor-Hood P2-P1 (``fem_baselines.unsaturated``) on its triangles. Under
``mpiexec`` both are distributed (RCB for the particles, dolfinx's partition for the mesh).

Measures, at every node: p and u of both methods; the largest difference of RKPM's p from
FEM's relative to FEM's pressure range, and of u relative to FEM's largest |u|; the discharge
(the seepage face's outflow, per metre of levee); the height where water leaves the downstream
slope (the highest point with p > 0 on it); the crest's settlement. The effective stress D eps(u) of
both at the nodes (FEM's strain is a discontinuous P1 field, held exactly in DG1), its largest
and rms difference over the interior nodes relative to FEM's largest stress component, and
its mobilized strength sqrt(J_2) / (k_c - a_phi I_1) of Drucker-Prager (1: at yield): where it
exceeds 1 and where it is largest (at the downstream toe, where the seed's shear band starts).

Stage 1b (``--set plastic=true``): the elastic-plastic state in that seepage
(``plastic_state``). From u = 0 and the steady pressures, gravity (the skeleton's weight, the
pore pressure's force and the river's traction) rises with a load factor from 0 to 1 in
``ramp_steps`` static steps (drained: the pressures stay the steady seepage's), the effective
stress following the Drucker-Prager return map (``UnsaturatedBiotModel(..., plasticity=,
ramp=)``); reported: the load factor reached (a Newton failure after 8 cuts ends the stage
there), the crest's settlement against it, the equivalent plastic strain and the largest yield
function (<= 0: admissible). The FEM baseline takes the same law at its quadrature points
(``FemUnsaturatedModel(..., plasticity=, ramp=)``).

Stage 1c (``--set collapse=true``, serial): the collapse load (``collapse_path``). From the same
start the settlement work-conjugate to gravity's loads (their mean settlement) is driven up to
``settlement_max`` in ``path_steps`` targets and the load factor found in each
(``rkfx.solvers.path_following``): it rises to the largest gravity the levee carries and
levels off there, where load control finds no equilibrium. Reported: the path, its peak (the
collapse load factor), the stiffness left at its end (near 0 on the plateau) and why it ended.
With the assumed dimensions the collapse load falls from above 1 to about a third of gravity
as the river rises from 0.4 to 0.8 m, RKPM without the NSNI terms (``rule=snni-vc``) and the
FEM within a few percent of each other; NSNI's elastic expansion terms harden the mechanism
(docs/large_deformation.md).

Stage 2, the dynamic collapse from this state on moving particles (``rkfx.models.
lagrangian_plasticity`` with the u-p flow), is not in this case yet: under NSNI the plastic
flow of the collapse still goes unstable at the advancing toe (docs/large_deformation.md).

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], rho_s, rho_w [kg/m^3], porosity
[-], conductivity [m/s], K_s, K_w [Pa], gravity [m/s^2], S_rw [-], vg_n [-], vg_beta [1/m],
phi [deg], cohesion [Pa], height, crest, slope_up, slope_down, water [m], h [m], rule,
first_step [s], plastic, ramp_steps, collapse, settlement_max [m], path_steps. The ramp and
the collapse path keep checkpoints (``--checkpoint-every N`` steps, ``--resume DIR``).

    python -m rkfx.cases.levee [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR]
"""
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from rkfx.approximation.semi_lagrangian import evaluate_moving
from rkfx.assembly.operators import strain_matrix
from rkfx.assembly.seepage_face import seepage_face
from rkfx.assembly.weighted_forms import placed
from rkfx.cases import _cli, _preflight
from rkfx.cases._cli import Param, Results, Run
from rkfx.cases._nodal_up import edge_load, nodal_discretization, owned, split_over_ranks, whole_unknowns
from rkfx.errors import InputError, SolverError
from rkfx.integration.nodal_stabilized import RULES
from rkfx.materials.drucker_prager import DruckerPrager, invariants
from rkfx.materials.retention import VanGenuchten
from rkfx.models.explicit_poroelasticity import Constituents, collocation_rows
from rkfx.models.unsaturated_poroelasticity import UnsaturatedBiotModel, UnsaturatedSoil
from rkfx.report.claims import Claim
from rkfx.solvers.integrate import integrate
from rkfx.solvers.model import Constraints, WithoutRates
from rkfx.solvers.newmark import backward_euler
from rkfx.solvers.path_following import follow
from rkfx.solvers.steady import steady_state

NAME = "levee"

PARAMS = {
    "E": Param(1.0e7, "drained Young's modulus [Pa]"),
    "nu": Param(0.3, "drained Poisson's ratio [-]"),
    "rho_s": Param(2700.0, "grain density [kg/m^3]"),
    "rho_w": Param(1000.0, "water density [kg/m^3]"),
    "porosity": Param(0.46, "porosity n [-]"),
    "conductivity": Param(5.0e-4, "hydraulic conductivity k gamma_w [m/s]"),
    "K_s": Param(1.0e22, "grain bulk modulus [Pa]"),
    "K_w": Param(1.0e9, "water bulk modulus [Pa]"),
    "gravity": Param(9.806, "gravitational acceleration [m/s^2]"),
    "S_rw": Param(0.0842, "residual saturation of van Genuchten's law [-]"),
    "vg_n": Param(2.0, "van Genuchten's n [-]"),
    "vg_beta": Param(0.7, "van Genuchten's beta [1/m]"),
    "phi": Param(20.0, "Drucker-Prager friction angle [deg]"),
    "cohesion": Param(300.0, "Drucker-Prager cohesion [Pa]"),
    "height": Param(1.0, "height of the levee [m]"),
    "crest": Param(0.5, "width of the crest [m]"),
    "slope_up": Param(2.0, "upstream slope, horizontal per vertical [-]"),
    "slope_down": Param(2.0, "downstream slope, horizontal per vertical [-]"),
    "water": Param(0.8, "river level against the upstream slope [m]"),
    "h": Param(0.05, "mesh size of the particles and the triangles [m]"),
    "rule": Param("nsni", "nodal integration rule of RKPM"),
    "first_step": Param(0.01, "first pseudo-time step of the steady march [s]"),
    "plastic": Param(False, "RKPM also computes the elastic-plastic state in the steady seepage (stage 1b)"),
    "ramp_steps": Param(20, "steps of the load factor from 0 to 1 in the elastic-plastic stage [-]"),
    "collapse": Param(False, "with plastic: also follow the mean settlement past the largest gravity the levee "
                             "carries (serial)"),
    "settlement_max": Param(0.05, "largest mean settlement (work-conjugate to gravity) of the collapse path [m]"),
    "path_steps": Param(40, "target settlements of the collapse path, evenly spaced up to settlement_max [-]"),
}
QUICK = {"h": 0.1}

#: Outflow per unit pressure of the seepage face, in units of k / h (``rkfx.assembly.seepage_face``).
PENALTY = 1e3


def _soil(E, nu, rho_s, rho_w, porosity, conductivity, K_s, K_w, gravity, S_rw, vg_n, vg_beta) -> UnsaturatedSoil:
    gamma_w = rho_w * gravity
    medium = Constituents(E=E, nu=nu, rho_s=rho_s, rho_f=rho_w, porosity=porosity, k=conductivity / gamma_w,
                          K_s=K_s, K_f=K_w)
    return UnsaturatedSoil(medium, VanGenuchten(S_rw=S_rw, n=vg_n, beta=vg_beta, gamma_w=gamma_w), gravity)


def sand(**params) -> UnsaturatedSoil:
    """The levee's sand of §6.4.3 (the defaults of ``PARAMS``, any of its soil data overridden)."""
    keys = ("E", "nu", "rho_s", "rho_w", "porosity", "conductivity", "K_s", "K_w", "gravity", "S_rw", "vg_n",
            "vg_beta")
    return _soil(**{k: params.get(k, PARAMS[k].default) for k in keys})


def check(*, E, nu, rho_s, rho_w, porosity, conductivity, K_s, K_w, gravity, S_rw, vg_n, vg_beta, phi, cohesion,
          height, crest, slope_up, slope_down, water, h, rule, first_step, plastic=False, ramp_steps=20,
          collapse=False, settlement_max=0.05, path_steps=40, **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    for name, v in (("conductivity", conductivity), ("height", height), ("crest", crest), ("slope_up", slope_up),
                    ("slope_down", slope_down), ("h", h), ("first_step", first_step), ("gravity", gravity)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be positive")
    _soil(E, nu, rho_s, rho_w, porosity, conductivity, K_s, K_w, gravity, S_rw, vg_n, vg_beta)
    DruckerPrager(E=E, nu=nu, phi=phi, c=cohesion)
    if not 0.0 < water < height:
        raise InputError(f"water = {water!r} must lie between the floor and the crest (0, {height})")
    if h > min(water, height - water, crest) / 2 * (1.0 + 1e-9):
        raise InputError(f"h = {h!r} is too coarse: take at most half of the smallest of the wet slope's height "
                         f"({water}), the dry slope's ({height - water:.4g}) and the crest ({crest})")
    if rule not in RULES:
        raise InputError(f"unknown nodal rule {rule!r}; choose from {', '.join(RULES)}")
    if not isinstance(plastic, (bool, np.bool_)):
        raise InputError(f"plastic = {plastic!r}: give true or false")
    if int(ramp_steps) != ramp_steps or ramp_steps < 1:
        raise InputError(f"ramp_steps = {ramp_steps!r} must be a whole number >= 1")
    if not isinstance(collapse, (bool, np.bool_)):
        raise InputError(f"collapse = {collapse!r}: give true or false")
    if collapse and not plastic:
        raise InputError("collapse = true follows the elastic-plastic skeleton: set plastic = true as well")
    if not (np.isfinite(settlement_max) and settlement_max > 0):
        raise InputError(f"settlement_max = {settlement_max!r} must be positive [m]")
    if int(path_steps) != path_steps or path_steps < 1:
        raise InputError(f"path_steps = {path_steps!r} must be a whole number >= 1")


def memory_need(methods, *, height, crest, slope_up, slope_down, h, **_) -> _preflight.Need:
    """Peak bytes: the RKPM u-p Jacobian (about 24 neighbours per row over 3 fields) and the
    P2-P1 one, with their factorizations, of a triangulation of ``h``."""
    area = height * (crest + 0.5 * (slope_up + slope_down) * height)
    nodes = area / (0.5 * np.sqrt(3.0) * h * h)
    return _preflight.need(3 * 6e3, nodes, f"h={h:g}", "raise h")


class Levee:
    """The trapezoid's corners and the parts of its boundary (x from the upstream toe)."""

    def __init__(self, height, crest, slope_up, slope_down, water):
        self.height, self.water = height, water
        self.top_up = slope_up * height
        self.top_down = self.top_up + crest
        self.toe = self.top_down + slope_down * height
        self.slope_down = slope_down
        self.wet = (slope_up * water, water)

    def river(self, gamma_w: float):
        """The river's water pressure at points x (m, 2), 0 above its level [Pa]."""
        return lambda x: gamma_w * np.maximum(self.water - x[:, 1], 0.0)

    def on_downstream(self, y: np.ndarray) -> np.ndarray:
        """Points of the downstream slope at heights ``y``, shape ``(m, 2)``."""
        return np.column_stack([self.toe - self.slope_down * y, y])

    def mesh(self, h: float):
        """Mesh the levee in the current gmsh session (rank 0): physical groups base,
        downstream, crest, upstream_dry, upstream_wet (curves) and levee (surface)."""
        import gmsh  # noqa: PLC0415

        model = gmsh.model
        model.add(f"{NAME}_{h:g}")
        geo = model.geo
        corners = [(0.0, 0.0), (self.toe, 0.0), (self.top_down, self.height), (self.top_up, self.height), self.wet]
        pts = [geo.addPoint(x, y, 0.0, h) for x, y in corners]
        names = ("base", "downstream", "crest", "upstream_dry", "upstream_wet")
        lines = [geo.addLine(pts[i], pts[(i + 1) % 5]) for i in range(5)]
        surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        for name, line in zip(names, lines):
            model.setPhysicalName(1, model.addPhysicalGroup(1, [line]), name)
        model.setPhysicalName(2, model.addPhysicalGroup(2, [surface]), "levee")
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        model.mesh.generate(2)
        return model


def _samplers(levee: Levee, nodes: np.ndarray, crest_mid: np.ndarray):
    """The points every method is sampled at: the nodes, the downstream slope, the crest's middle."""
    ys = np.linspace(0.0, levee.height, 201)
    return np.vstack([nodes, levee.on_downstream(ys), crest_mid[None, :]]), ys


def rkpm_levee(p, soil: UnsaturatedSoil, levee: Levee, h: float, rule: str, points: np.ndarray, comm=None,
               plasticity: DruckerPrager | None = None, ramp=None, d=None):
    """The RKPM model of the levee on particles ``p`` and its sampler of [p..., u_x..., u_y...]
    at ``points`` (on ranks: collective, every rank gets all of them); with ``plasticity`` the
    skeleton is elastic-plastic, its loads scaled by ``ramp(t)``; ``d``: the nodal
    discretization of an earlier model of the same particles, reused."""
    d = nodal_discretization(p, h, rule, comm) if d is None else d
    n, x = p.num_nodes, p.x
    size = 3 * n
    base, wet = owned(d, p.boundary_nodes("base")), owned(d, p.boundary_nodes("upstream_wet"))
    river = levee.river(soil.medium.rho_f * soil.gravity)
    G = sp.vstack([collocation_rows(d.rk, base, 0, n, 0, size), collocation_rows(d.rk, base, 1, n, 0, size),
                   collocation_rows(d.rk, wet, None, n, 2 * n, size)]).tocsr()
    g = np.r_[np.zeros(2 * len(base)), river(x[wet])]
    edges = p.boundary_edges
    face = seepage_face(d.rk, edges[p.boundary_tags == p.tag("downstream")], PENALTY * soil.medium.k / h, nodes=d.own)
    wet_edges = edges[p.boundary_tags == p.tag("upstream_wet")]
    load = np.zeros(size)  # the whole force on every rank; the model keeps the rank's owned entries
    load[:2 * n] = edge_load(d.rk, wet_edges, lambda xs, normal: -river(xs)[:, None] * normal)
    nearest = cKDTree(x).query(points)[1]
    rows = evaluate_moving(d.rk, points, nearest).matrix().tocsr()
    rows = sp.vstack([placed(rows, size, 2 * n), placed(rows, size, 0, 2), placed(rows, size, 1, 2)]).tocsr()
    local, (G,), sample = split_over_ranks(d, comm, [G], rows,
                                           touching=sp.vstack([G, placed(face.matrix(), size, 2 * n), rows]))
    model = UnsaturatedBiotModel(d.rule, soil, Constraints(G, g), local, seepage=face, weight="full", load=load,
                                 plasticity=plasticity, ramp=ramp)
    return model, sample, d


def fem_levee(mesh_data, soil: UnsaturatedSoil, levee: Levee, h: float, points: np.ndarray,
              plasticity: DruckerPrager | None = None, ramp=None):
    """The Taylor-Hood model of the levee on the gmsh triangles, its sampler (as ``rkpm_levee``)
    and the strains at the first sample points (collective on ranks); ``plasticity`` and
    ``ramp`` as for ``rkpm_levee``."""
    import dolfinx_solver  # noqa: F401, PLC0415

    import dolfinx  # noqa: PLC0415
    import ufl  # noqa: PLC0415

    from fem_baselines.poroelasticity import _Sampler  # noqa: PLC0415
    from fem_baselines.unsaturated import FemUnsaturatedModel  # noqa: PLC0415
    from rkfx.conditions import Displacement, Pressure, Traction  # noqa: PLC0415

    river = levee.river(soil.medium.rho_f * soil.gravity)
    conditions = [Displacement("base"), Pressure("upstream_wet", lambda x, t: river(x)),
                  Traction("upstream_wet", lambda x, t, n: -river(x)[:, None] * n)]
    model = FemUnsaturatedModel(mesh_data.mesh, soil, conditions, seepage=("downstream", PENALTY * soil.medium.k / h),
                                weight="full", facet_tags=mesh_data.facet_tags,
                                physical_groups=mesh_data.physical_groups, plasticity=plasticity, ramp=ramp)
    sampler = _Sampler(mesh_data.mesh, points)
    mesh = mesh_data.mesh
    # the strain of the P2 displacement is a discontinuous P1 field: held exactly in DG1
    strain_space = dolfinx.fem.functionspace(mesh, ("DG", 1, (2, 2)))
    strain = dolfinx.fem.Function(strain_space)
    strain_of_u = dolfinx.fem.Expression(ufl.sym(ufl.grad(model.uh)), strain_space.element.interpolation_points)

    def sample(x):
        model.assign(x, model.uh, model.ph)
        p, u = sampler(model.uh, model.ph)
        return np.r_[p, u[:, 0], u[:, 1]]

    def strains(x, nodes):
        """(eps_xx, eps_yy, gamma_xy) at the first ``nodes`` sample points."""
        model.assign(x, model.uh, model.ph)
        strain.interpolate(strain_of_u)
        e = sampler.field(strain)[:nodes]
        return np.column_stack([e[:, 0], e[:, 3], e[:, 1] + e[:, 2]])

    return model, sample, strains


class _Ramp:
    """The load factor and the crest's settlement of every committed step of the plastic stage."""

    def __init__(self, sample, points: int):
        self.sample, self.points, self.rows, self.x = sample, points, [], None

    def record(self, s) -> None:
        self.rows.append((s.t, float(-self.sample(s.x)[2 * self.points:][-1])))
        self.x = s.x

    def arrays(self):
        return {"ramp": np.array(self.rows)}

    def restore(self, a) -> None:
        self.rows = [tuple(r) for r in a["ramp"]]


def plastic_state(model, sample, points: int, elastic_x: np.ndarray, steps: int, comm, **checkpoints) -> dict:
    """Stage 1b: the skeleton's elastic-plastic equilibrium in the steady seepage of ``elastic_x``.

    ``model`` is the method's levee with ``plasticity`` and the load factor ``ramp(t) = t``
    (``rkpm_levee``, ``fem_levee``). From u = 0 and the steady pressures, the skeleton's loads
    (its weight, the pore pressure's force alpha S_w p and the river's traction, i.e. gravity)
    rise from 0 to 1 in ``steps`` backward Euler steps, the stress following the Drucker-Prager
    return map. The steps are static (``WithoutRates``): a drained loading, the pressures those
    of the steady seepage. A step whose Newton fails is cut (up to 8 times); if it still fails,
    the stage ends there (a sign, not a proof, that no static equilibrium lies beyond:
    ``collapse_path`` finds the largest load). Returns the lambda reached, the crest's
    settlement against lambda, the committed stress and equivalent plastic strain at the
    model's points (this rank's), and the largest change of the sampled pressures [Pa].
    ``checkpoints``: ``checkpoint_every``, ``checkpoint_dir``, ``resume`` of ``integrate``."""
    x0 = np.array(elastic_x, float)
    x0[model.layout.block("u")] = 0.0
    stepper = backward_euler()
    ramp = _Ramp(sample, points)
    why = "reached lambda = 1"
    static = WithoutRates(model)  # drained: the pressures keep the steady seepage, whatever the pseudo-time
    try:
        run = integrate(stepper, static, np.linspace(0.0, 1.0, steps + 1), start=stepper.start(static, x0),
                        recorder=ramp, comm=comm, max_cuts=8, **checkpoints)
        newton, cuts, x = run.newton_iterations, run.cuts, run.state.x
    except SolverError as err:
        why, newton, cuts, x = f"stopped: {err}", None, None, (x0 if ramp.x is None else ramp.x)
    stress, plastic = model.plastic_state
    rows = np.array(ramp.rows) if ramp.rows else np.zeros((0, 2))
    pressures = sample(x)[:points] - sample(x0)[:points]
    return {"lambda_reached": float(rows[-1, 0]) if len(rows) else 0.0, "why": why, "newton_iterations": newton,
            "cuts": cuts, "ramp": rows, "stress": stress, "plastic_strain": plastic,
            "pressure_change": float(np.abs(pressures).max())}


#: The collapse path ends where the load factor grew less than this over the last doubling of the settlement.
LEVELLED = 2e-3


def collapse_path(model, elastic_x: np.ndarray, settlement_max: float, steps: int, comm, **checkpoints) -> dict:
    """Stage 1c: gravity's load factor lambda along the path of the levee's mean settlement.

    ``model`` is the method's levee with ``plasticity``, the load factor ``ramp(t) = t`` and
    its history unstressed. From u = 0 in the steady seepage of ``elastic_x`` (drained: the
    loads f at lambda = 1 stay fixed), the settlement work-conjugate to them,
    d = f . u / W with W = f . (0, -1) the levee's weight (a uniform settlement s gives d = s),
    is driven from 0 to ``settlement_max`` in ``steps`` targets and lambda found in each
    (``rkfx.solvers.path_following``). For a stable (associated) plastic solid lambda(d) rises
    to the collapse load and levels off; the path ends early where it has (grown less than
    ``LEVELLED`` over the last doubling of d). Returns the path (d, lambda), its peak, the
    line through its second half (slope, and intercept at d = 0: the collapse load less a
    hardening, e.g. of a stabilization) and that slope over the first step's (the stiffness
    left: near 0 on a plateau). ``checkpoints``: ``checkpoint_every``,
    ``checkpoint_dir``, ``resume`` of ``follow``."""
    x0 = np.array(elastic_x, float)
    u = model.layout.block("u")
    x0[u] = 0.0
    model.residual(x0, 1.0)  # a trial only: the loads at lambda = 1
    f = -model.load_derivative()
    down = np.zeros_like(x0)
    down[u] = np.tile([0.0, -1.0], len(x0[u]) // 2)
    control = f / float(f @ down)

    def levelled(s, path) -> bool:
        d, t = path.T
        return bool(s.d >= 4.0 * d[1] and s.t <= (1.0 + LEVELLED) * np.interp(0.5 * s.d, d, t))

    run = follow(model, control, np.linspace(0.0, settlement_max, steps + 1)[1:], x0, 0.0, until=levelled, comm=comm,
                 **checkpoints)
    d, t = run.path.T
    late = d >= 0.5 * d[-1]
    slope, intercept = np.polyfit(d[late], t[late], 1) if late.sum() >= 2 else (0.0, float(t[-1]))
    return {"path": run.path, "lambda_peak": float(t.max()), "lambda_end": float(t[-1]), "settlement_end": float(d[-1]),
            "slope": float(slope), "stiffness_left": float(slope / ((t[1] - t[0]) / (d[1] - d[0]))) if len(d) > 1 else float("nan"), "intercept": float(intercept), "ended": run.ended, "message": run.message,
            "steps": run.steps, "cuts": run.cuts, "newton_iterations": run.iterations, "wall_s": run.wall_time_s}


def _rkpm_strains(model, x: np.ndarray) -> np.ndarray:
    """(eps_xx, eps_yy, gamma_xy) of RKPM at its integration points, by the rule's trial gradients."""
    return (strain_matrix(model.rule.trial) @ x[:2 * model.n]).reshape(-1, 3)


def _strength(strains: np.ndarray, soil: UnsaturatedSoil, phi: float, cohesion: float):
    """The effective stress D eps (m, 4) and its mobilized Drucker-Prager strength
    sqrt(J_2) / (k_c - a_phi I_1) (1: at yield)."""
    m = soil.medium
    dp = DruckerPrager(E=m.E, nu=m.nu, phi=phi, c=cohesion)
    stress = dp.elastic_increment(strains)
    i1, sqrt_j2, _ = invariants(stress)
    return stress, sqrt_j2 / np.maximum(dp.k_c - dp.a_phi * i1, 1e-30)


def _largest(values: np.ndarray, comm) -> float:
    """The largest of ``values`` over every rank (collective on ranks)."""
    local = float(np.max(values, initial=-np.inf))
    return local if comm is None or comm.size == 1 else max(comm.allgather(local))


def _at_nodes(d, values: np.ndarray, comm) -> np.ndarray:
    """Values at the rule's points (every node, or on ranks the rank's own) as an array over all
    nodes on every rank (collective on ranks)."""
    if d.own is None:
        return values
    full = np.zeros((d.particles.num_nodes, *values.shape[1:]))
    for nodes, part in comm.allgather((d.own, values)):
        full[nodes] = part
    return full


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=1.0e7, nu=0.3, rho_s=2700.0, rho_w=1000.0, porosity=0.46,
        conductivity=5.0e-4, K_s=1.0e22, K_w=1.0e9, gravity=9.806, S_rw=0.0842, vg_n=2.0, vg_beta=0.7, phi=20.0,
        cohesion=300.0, height=1.0, crest=0.5, slope_up=2.0, slope_down=2.0, water=0.8, h=0.05, rule="nsni",
        first_step=0.01, plastic=False, ramp_steps=20, collapse=False, settlement_max=0.05, path_steps=40,
        checkpoint_every=0, work_dir=None, resume=None) -> Results:
    """The initial state by both methods on one triangulation; see the module docstring."""
    prm = dict(E=E, nu=nu, rho_s=rho_s, rho_w=rho_w, porosity=porosity, conductivity=conductivity, K_s=K_s, K_w=K_w,
               gravity=gravity, S_rw=S_rw, vg_n=vg_n, vg_beta=vg_beta, phi=phi, cohesion=cohesion, height=height,
               crest=crest, slope_up=slope_up, slope_down=slope_down, water=water, h=h, rule=rule,
               first_step=first_step, plastic=plastic, ramp_steps=ramp_steps, collapse=collapse,
               settlement_max=settlement_max, path_steps=path_steps)
    check(**prm)
    soil = _soil(E, nu, rho_s, rho_w, porosity, conductivity, K_s, K_w, gravity, S_rw, vg_n, vg_beta)
    levee = Levee(height, crest, slope_up, slope_down, water)
    comm = _cli.comm()
    rank = comm.rank if comm is not None else 0
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    if collapse and comm is not None and comm.size > 1:
        raise InputError(f"collapse = true runs serially (its path's bordered row is global), not on {comm.size} "
                         "ranks: run it without mpiexec")
    import gmsh  # noqa: PLC0415

    from rkfx.geometry.gmsh_nodes import from_gmsh  # noqa: PLC0415
    started = gmsh.isInitialized()
    if not started:
        gmsh.initialize(interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    results = Results(NAME, {**prm, "stage": "initial state"})
    try:
        if rank == 0:
            levee.mesh(h)
        p = from_gmsh(gmsh.model, comm)
        crest_mid = np.array([0.5 * (levee.top_up + levee.top_down), height])
        points, ys = _samplers(levee, p.x, crest_mid)
        n = p.num_nodes
        results.params.update(nodes=n, triangles=len(p.triangles))
        found = {}
        for method in methods:
            label = f"rkpm-{rule}" if method == "rkpm" else "fem-taylor-hood"
            t0 = time.perf_counter()
            with _cli.model_run(label):
                if method == "rkpm":
                    model, sample, d = rkpm_levee(p, soil, levee, h, rule, points, comm)
                else:
                    from fem_baselines.gmsh_mesh import mesh_from_gmsh  # noqa: PLC0415
                    mesh_data = mesh_from_gmsh(gmsh.model if rank == 0 else None, comm, gdim=2)
                    model, sample, fem_strains = fem_levee(mesh_data, soil, levee, h, points)
                done = steady_state(model, first_step, comm=comm)
            x = done.state.x
            values = sample(x)
            m = len(points)
            pv, ux, uy = values[:m], values[m:2 * m], values[2 * m:]
            slope_p = pv[n:n + len(ys)]
            series = {"x": p.x[:, 0], "y": p.x[:, 1], "triangles": p.triangles, "p": pv[:n], "ux": ux[:n],
                      "uy": uy[:n], "slope_y": ys, "slope_p": slope_p}
            info = {"steps": done.run.steps, "newton_iterations": done.run.newton_iterations, "cuts": done.run.cuts,
                    "pseudo_time": float(done.times[-1]), "outflow": float(model.seepage_outflow(x)),
                    "exit_height": float(ys[slope_p > 0.0].max(initial=0.0)), "crest_settlement": float(-uy[-1]),
                    "max_displacement": float(np.hypot(ux[:n], uy[:n]).max())}
            if method == "rkpm":
                strains = _at_nodes(d, _rkpm_strains(model, x), comm)
                flux = _at_nodes(d, model.darcy_flux(x), comm)
                series.update(qx=flux[:, 0], qy=flux[:, 1])
            else:
                strains = fem_strains(x, n)
            stress, ratio = _strength(strains, soil, phi, cohesion)
            series.update(strength=ratio, sxx=stress[:, 0], syy=stress[:, 1], sxy=stress[:, 3])
            worst = int(np.argmax(ratio))
            info.update(strength_max=float(ratio.max()), strength_max_x=float(p.x[worst, 0]),
                        strength_max_y=float(p.x[worst, 1]), yielded_nodes=int(np.sum(ratio >= 1.0)))
            found[method] = (pv[:n], ux[:n], uy[:n], stress)
            if plastic:
                dp = DruckerPrager(E=E, nu=nu, phi=phi, c=cohesion)
                if method == "rkpm":
                    pmodel, psample, _ = rkpm_levee(p, soil, levee, h, rule, points, comm, plasticity=dp,
                                                    ramp=lambda t: t, d=d)
                else:
                    pmodel, psample, _ = fem_levee(mesh_data, soil, levee, h, points, plasticity=dp,
                                                   ramp=lambda t: t)
                unstressed = pmodel.state()
                stage = plastic_state(pmodel, psample, len(points), x, int(ramp_steps), comm,
                                      **ck.for_run(f"{label}-ramp"))
                ramp = stage["ramp"]
                if method == "rkpm":  # at the nodes (the particles' own points on ranks)
                    eps_p, stress_p = _at_nodes(d, stage["plastic_strain"], comm), _at_nodes(d, stage["stress"], comm)
                    worst = int(np.argmax(eps_p))
                    where = dict(plastic_strain_max_x=float(p.x[worst, 0]), plastic_strain_max_y=float(p.x[worst, 1]),
                                 plastic_nodes=int(np.sum(eps_p > 1e-3)))
                    series.update(plastic_strain=eps_p)
                else:  # at the quadrature points: the largest over the ranks
                    eps_p, stress_p = stage["plastic_strain"], stage["stress"]
                    where = {}
                info.update(lambda_reached=stage["lambda_reached"], plastic_why=stage["why"],
                            plastic_newton_iterations=stage["newton_iterations"], plastic_cuts=stage["cuts"],
                            plastic_crest_settlement=float(ramp[-1, 1]) if len(ramp) else 0.0,
                            plastic_strain_max=_largest(eps_p, comm), **where,
                            plastic_pressure_change=stage["pressure_change"],
                            plastic_yield_excess=_largest(dp.yield_function(stress_p), comm) / dp.k_c)
                series.update(ramp_lambda=ramp[:, 0], ramp_settlement=ramp[:, 1])
                if collapse:
                    pmodel.restore(unstressed)
                    path = collapse_path(pmodel, x, float(settlement_max), int(path_steps), comm,
                                         **ck.for_run(f"{label}-collapse"))
                    info.update({f"collapse_{k}": v for k, v in path.items() if k != "path"})
                    series.update(collapse_settlement=path["path"][:, 0], collapse_lambda=path["path"][:, 1])
                    if method == "rkpm":  # the mechanism: the plastic strain at the path's end
                        series.update(collapse_plastic_strain=_at_nodes(d, pmodel.plastic_state[1], comm))
            results.runs.append(Run(label, time.perf_counter() - t0, whole_unknowns(model), series=series, info=info))
        if rank == 0:
            gmsh.model.remove()
    finally:
        if not started:
            gmsh.finalize()
    if {"rkpm", "fem"} <= set(found):
        rk = next(r for r in results.runs if r.method.startswith("rkpm"))
        fem = next(r for r in results.runs if r.method.startswith("fem"))
        (pr, uxr, uyr, sr), (pf, uxf, uyf, sf) = found["rkpm"], found["fem"]
        inside = ~np.isin(np.arange(len(pr)), np.unique(p.boundary_edges))
        scale = np.abs(sf[inside][:, [0, 1, 3]]).max()
        rk.errors["stress_interior"] = float(np.abs(sr - sf)[inside][:, [0, 1, 3]].max() / scale)
        rk.errors["stress_rms"] = float(np.sqrt(np.mean((sr - sf)[inside][:, [0, 1, 3]] ** 2)) / scale)
        rk.errors["p_max"] = float(np.abs(pr - pf).max() / (pf.max() - pf.min()))
        rk.errors["u_max"] = float(np.hypot(uxr - uxf, uyr - uyf).max() / np.hypot(uxf, uyf).max())
        for key in ("outflow", "crest_settlement"):  # relative to FEM's (to RKPM's where FEM's is 0: a low river)
            a, b = rk.info[key], fem.info[key]
            rk.errors[key] = float(abs(a - b) / (abs(b) or abs(a) or 1.0))
        rk.errors["exit_height"] = float(abs(rk.info["exit_height"] - fem.info["exit_height"]))
    return results


def plot(results: Results, out: Path) -> list[Path]:
    """Pressure maps with the water table and Darcy's flux (RKPM, FEM, their difference), the
    pressure along the downstream slope, the mobilized strength (RKPM's map, both yield lines);
    the crest's settlement."""
    import matplotlib.tri as mtri  # noqa: PLC0415
    from matplotlib.ticker import MaxNLocator  # noqa: PLC0415

    plt = _cli.pyplot()
    prm = results.params
    levee = Levee(prm["height"], prm["crest"], prm["slope_up"], prm["slope_down"], prm["water"])
    runs = {r.method.split("-")[0]: r for r in results.runs}
    any_run = next(iter(runs.values()))
    s = any_run.series
    tri = mtri.Triangulation(np.asarray(s["x"]), np.asarray(s["y"]), np.asarray(s["triangles"]))
    fig = plt.figure(figsize=(14, 15), layout="constrained")
    grid = fig.add_gridspec(4, 2, height_ratios=[1.0, 1.0, 1.25, 1.0])
    maps = [fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, :])]
    a_diff, a_slope = fig.add_subplot(grid[2, 0]), fig.add_subplot(grid[2, 1])
    a_str = fig.add_subplot(grid[3, :])
    outline = np.array([[0.0, 0.0], [levee.toe, 0.0], [levee.top_down, levee.height], [levee.top_up, levee.height],
                        [0.0, 0.0]])
    lo = min(float(np.min(r.series["p"])) for r in runs.values()) / 1e3
    hi = max(float(np.max(r.series["p"])) for r in runs.values()) / 1e3
    levels = MaxNLocator(nbins=24).tick_values(lo, hi)
    for ax, key in zip(maps, ("rkpm", "fem")):
        ax.set_aspect("equal")
        ax.plot(outline[:, 0], outline[:, 1], color="k", lw=0.8)
        ax.plot([-0.4, levee.wet[0]], [levee.water, levee.water], color="tab:blue", lw=2.0)
        if key not in runs:
            ax.text(0.5, 0.5, f"{key.upper()}: not run", ha="center", va="center", transform=ax.transAxes)
            ax.set_axis_off()
            continue
        r = runs[key]
        pk = np.asarray(r.series["p"]) / 1e3
        c = ax.tricontourf(tri, pk, levels=levels, cmap="viridis")
        ax.tricontour(tri, pk, levels=[0.0], colors="w", linewidths=1.6)
        if "qx" in r.series:
            xy = np.column_stack([r.series["x"], r.series["y"]])
            gx, gy = np.meshgrid(np.arange(0.05, levee.toe, 0.15), np.arange(0.04, levee.height, 0.12))
            pick = np.unique(cKDTree(xy).query(np.column_stack([gx.ravel(), gy.ravel()]), distance_upper_bound=0.05)[1])
            pick = pick[pick < len(xy)]
            qx, qy = np.asarray(r.series["qx"]), np.asarray(r.series["qy"])
            ax.quiver(xy[pick, 0], xy[pick, 1], qx[pick], qy[pick], color="k", alpha=0.6, width=0.0015,
                      scale=40.0 * float(np.percentile(np.hypot(qx, qy), 90)), scale_units="width")
        fig.colorbar(c, ax=ax, label="p [kPa]", shrink=0.9)
        ax.set_title(f"{r.method}: water pressure, water table (white){', Darcy flux' if 'qx' in r.series else ''}; "
                     f"outflow {r.info['outflow']:.3e} m^2/s", fontsize=9)
    a_diff.set_aspect("equal")
    a_diff.plot(outline[:, 0], outline[:, 1], color="k", lw=0.8)
    if {"rkpm", "fem"} <= set(runs):
        diff = (np.asarray(runs["rkpm"].series["p"]) - np.asarray(runs["fem"].series["p"])) / 1e3
        span = float(np.abs(diff).max()) or 1.0
        c = a_diff.tricontourf(tri, diff, levels=np.linspace(-span, span, 21), cmap="RdBu_r")
        fig.colorbar(c, ax=a_diff, label="p_RKPM - p_FEM [kPa]", shrink=0.8)
        a_diff.set_title(f"RKPM - FEM: at most {runs['rkpm'].errors['p_max']:.2%} of the pressure range", fontsize=9)
    else:
        a_diff.text(0.5, 0.5, "RKPM - FEM: both methods are needed\n(--method both)", ha="center", va="center",
                    transform=a_diff.transAxes)
    for key, r in runs.items():
        style = dict(color="k", ls="--", lw=1.6) if key == "fem" else dict(color="C1", lw=1.2)
        a_slope.plot(np.asarray(r.series["slope_p"]) / 1e3, r.series["slope_y"], **style,
                     label=f"{r.method}: water leaves below y = {r.info['exit_height']:.3f} m")
    a_slope.axvline(0.0, color="0.5", lw=0.6)
    a_slope.set_xlabel("p on the downstream slope [kPa]")
    a_slope.set_ylabel("height y [m]")
    a_slope.set_title("seepage face: p <= 0, outflow where p = 0", fontsize=9)
    a_slope.legend(fontsize=8)
    a_slope.grid(alpha=0.3)
    a_str.set_aspect("equal")
    a_str.plot(outline[:, 0], outline[:, 1], color="k", lw=0.8)
    if "rkpm" in runs and "strength" in runs["rkpm"].series:
        r = runs["rkpm"]
        ratio = np.asarray(r.series["strength"])
        c = a_str.tricontourf(tri, ratio, levels=np.linspace(0.0, 2.0, 21), cmap="magma", extend="max")
        a_str.tricontour(tri, ratio, levels=[1.0], colors="c", linewidths=1.2)
        if "fem" in runs:
            a_str.tricontour(tri, np.asarray(runs["fem"].series["strength"]), levels=[1.0], colors="w",
                             linewidths=1.2, linestyles="--")
        a_str.plot([r.info["strength_max_x"]], [r.info["strength_max_y"]], "c*", ms=12)
        fig.colorbar(c, ax=a_str, label="sqrt(J2) / (k_c - a_phi I1)", shrink=0.8)
        fem_note = ""
        if "fem" in runs:
            fem_note = (f"\nFEM's yield line dashed white ({runs['fem'].info['yielded_nodes']} nodes beyond); RKPM - FEM "
                        f"effective stress {r.errors['stress_rms']:.2%} rms, {r.errors['stress_interior']:.2%} at most "
                        "(interior nodes, of FEM's largest component)")
        a_str.set_title(f"RKPM, the elastic state: mobilized Drucker-Prager strength (phi {prm['phi']:g} deg, c "
                        f"{prm['cohesion']:g} Pa); beyond yield (cyan: 1) at {r.info['yielded_nodes']} of "
                        f"{len(ratio)} nodes, largest {r.info['strength_max']:.2f} (star){fem_note}", fontsize=9)
    for ax in (*maps, a_diff, a_str):
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    settle = ", ".join(f"{1e3 * r.info['crest_settlement']:.3f} mm ({r.method.split('-')[0].upper()})"
                       for r in runs.values())
    fig.suptitle(f"Levee (§6.4.3), initial state: steady seepage under gravity, river at {prm['water']:g} m, "
                 f"h = {prm['h']:g} m, {prm['nodes']} nodes; the crest settles {settle}")
    paths = [_cli.save(fig, out / "initial_state.png")]
    if "rkpm" in runs and "plastic_strain" in runs["rkpm"].series:
        paths.append(_plot_plastic(runs, tri, outline, prm, plt, out))
    return paths


def _plot_plastic(runs: dict, tri, outline, prm, plt, out: Path) -> Path:
    """The elastic-plastic stage: RKPM's equivalent plastic strain, and the crest's settlement
    against the load factor of every method run."""
    from matplotlib.colors import LogNorm  # noqa: PLC0415

    r = runs["rkpm"]
    info, s = r.info, r.series
    fig = plt.figure(figsize=(15, 8.5), layout="constrained")
    grid = fig.add_gridspec(2, 3, height_ratios=[1.0, 1.0], width_ratios=[1.0, 1.0, 1.25])
    a_map, a_ramp = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, 0])
    a_map.set_aspect("equal")
    a_map.plot(outline[:, 0], outline[:, 1], color="k", lw=0.8)
    at_collapse = "collapse_plastic_strain" in s
    eps_p = np.maximum(np.asarray(s["collapse_plastic_strain" if at_collapse else "plastic_strain"]), 1e-6)
    top = max(int(np.ceil(np.log10(eps_p.max()))), -5)
    c = a_map.tricontourf(tri, eps_p, levels=np.logspace(-6, top, 4 * (top + 6) + 1), norm=LogNorm(), cmap="inferno")
    a_map.tricontour(tri, np.asarray(s["p"]), levels=[0.0], colors="c", linewidths=1.2)
    if not at_collapse:
        a_map.plot([info["plastic_strain_max_x"]], [info["plastic_strain_max_y"]], "c*", ms=12)
    fig.colorbar(c, ax=a_map, label="equivalent plastic strain", shrink=0.9, ticks=10.0 ** np.arange(-6, top + 1))
    a_map.set_xlabel("x [m]")
    a_map.set_ylabel("y [m]")
    if at_collapse:
        a_map.set_title(f"{r.method}, the collapse mechanism: equivalent plastic strain at the collapse path's end "
                        f"(lambda {info['collapse_lambda_end']:.3g}, largest {eps_p.max():.3g}), water table (cyan)",
                        fontsize=9)
    else:
        a_map.set_title(f"{r.method}, elastic-plastic at lambda {info['lambda_reached']:.3g}: equivalent plastic strain "
                        f"(largest {info['plastic_strain_max']:.3g} at the star; above 1e-3 at {info['plastic_nodes']} "
                        "nodes), water table (cyan)", fontsize=9)
    for key, run in runs.items():
        if "ramp_lambda" not in run.series:
            continue
        color = "C3" if key == "rkpm" else "k"
        a_ramp.plot(np.asarray(run.series["ramp_lambda"]), 1e3 * np.asarray(run.series["ramp_settlement"]), "o-",
                    ms=3, color=color, label=f"{run.method}, elastic-plastic (lambda reached {run.info['lambda_reached']:.3g})")
        lam = np.linspace(0.05, 1.0, 20)  # the elastic settlement grows with the load factor
        a_ramp.plot(lam, 1e3 * run.info["crest_settlement"] * lam, "--", color=color, alpha=0.5,
                    label=f"{run.method}, elastic")
    a_ramp.set_yscale("log")
    a_ramp.set_xlabel("load factor lambda (gravity)")
    a_ramp.set_ylabel("crest settlement [mm]")
    a_ramp.legend(fontsize=7)
    a_ramp.grid(alpha=0.3)
    collapse = {key: run for key, run in runs.items() if "collapse_lambda" in run.series}
    if collapse:
        _plot_collapse(fig.add_subplot(grid[1, 1]), collapse)
    text = fig.add_subplot(grid[1, 2] if collapse else grid[1, 1:])
    text.set_axis_off()
    text.text(0.0, 0.98, "\n".join([
        f"river at {prm['water']:g} m, h = {prm['h']:g} m, {prm['nodes']} nodes",
        "steady seepage (elastic march), then gravity raised",
        f"from 0 to 1 in {prm['ramp_steps']} drained steps (load control):",
        *[f"  {run.method}: lambda reached {run.info['lambda_reached']:.3g}, crest settlement "
          f"{1e3 * run.info['plastic_crest_settlement']:.3g} mm" for run in runs.values() if "lambda_reached" in run.info],
        f"  {r.method}: elastic {1e3 * info['crest_settlement']:.3g} mm, largest f / k_c = {info['plastic_yield_excess']:.2g}",
        *(["collapse path (settlement driven):"] if collapse else []),
        *[f"  {run.method}: lambda peaks at {run.info['collapse_lambda_peak']:.3g}, stiffness left "
          f"{run.info['collapse_stiffness_left']:.2g}, ended: {run.info['collapse_ended']}" for run in collapse.values()]]),
        va="top", fontsize=9)
    fig.suptitle(f"Levee (§6.4.3), stage 1b{'/1c' if collapse else ''}: the elastic-plastic state in the steady "
                 f"seepage{' and its collapse load' if collapse else ''} (Drucker-Prager phi "
                 f"{prm['phi']:g} deg, c {prm['cohesion']:g} Pa)")
    return _cli.save(fig, out / "plastic_state.png")


def _plot_collapse(ax, runs: dict) -> None:
    """The collapse paths: gravity's load factor against the crest's mean settlement."""
    for key, run in runs.items():
        d, lam = 1e3 * np.asarray(run.series["collapse_settlement"]), np.asarray(run.series["collapse_lambda"])
        color = "C3" if key == "rkpm" else "k"
        ax.plot(d, lam, "o-", ms=2, color=color, label=f"{run.method} (peak {lam.max():.3g})")
    ax.axhline(1.0, color="C0", lw=0.8, ls=":", label="full gravity")
    ax.set_xlabel("mean settlement (work-conjugate to gravity) [mm]")
    ax.set_ylabel("load factor lambda (gravity)")
    ax.set_title("collapse path (settlement driven)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)


CLAIMS = [
    Claim("Fig 6.10, initial state: RKPM's steady pressure within 2 % of the FEM baseline's (of the pressure range)",
          run="rkpm-nsni", key="p_max", op="<", bound=0.02),
    Claim("Fig 6.10, initial state: RKPM's seepage outflow within 2 % of the FEM baseline's",
          run="rkpm-nsni", key="outflow", op="<", bound=0.02),
    Claim("Fig 6.10, initial state: RKPM's displacement within 5 % of the FEM baseline's (of its largest)",
          run="rkpm-nsni", key="u_max", op="<", bound=0.05),
    Claim("Fig 6.10, initial state: RKPM's effective stress within 2 % rms of the FEM baseline's (interior nodes)",
          run="rkpm-nsni", key="stress_rms", op="<", bound=0.02),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
