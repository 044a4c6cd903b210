"""A pre-existing fracture on a mesh cut along it: the node-to-node faces of the crack-band FEM.

The mesh's vertices are the particles of ``rkfx.geometry.particles.cut_triangulation``: every
vertex of the fracture is there twice, one copy per face, 2 gap (1e-8 h) apart, and no triangle
straddles the fracture. The two faces are the boundary edges of the cut named after the
fracture. ``FractureFaces`` pairs the copies: for each vertex of the + face (the side that the
fracture's normal n_C points to; n_C the right-hand normal of the fracture's segment, as in
``rkfx.fracture.contact``) its copy on the - face, with the weight of half the length of the
face edges at the vertex. ``nodal_interface`` turns the pairs into the ``Interface`` rows of
the contact law over a P1 model's unknowns:

    g_N = (u_+ - u_-) . n_C,   g_T = (u_+ - u_-) . t_C,   p_C = (p_+ + p_-) / 2

at every pair, integrated by the trapezoidal rule along the fracture (nodal quadrature). With
linear elements the jump is linear along each face edge; the nodal rule keeps the contact
points where the unknowns are, so a penalty face neither locks nor oscillates (the usual
choice for node-to-node contact), and a jump that the law balances uniformly along the
fracture is carried exactly (``tests/test_fem_fracture.py``).

Flow: the elements with a vertex on either face carry the fracture's permeability
(``rkfx.fracture.contact.FractureContact`` with those elements as carriers), as the particles
whose supports reach the fracture do in the RKPM model.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from rkfx.errors import InputError
from rkfx.fracture.contact import Interface, directional_rows
from rkfx.geometry.particles import Particles

__all__ = ["FractureFaces", "fracture_faces", "nodal_interface", "touching"]


@dataclass(frozen=True)
class FractureFaces:
    """The vertex pairs of a cut fracture (module docstring).

    Attributes:
        plus, minus: Coordinates of the + face copy and of its - face partner, shape ``(m, 2)`` [m].
        weights: Half the length of the face edges at each pair, shape ``(m,)`` [m].
        normal: n_C at each pair (from the - side to the + side), shape ``(m, 2)``.
    """

    plus: np.ndarray
    minus: np.ndarray
    weights: np.ndarray
    normal: np.ndarray

    @property
    def num_pairs(self) -> int:
        return len(self.weights)


def fracture_faces(p: Particles, name: str, segment: np.ndarray) -> FractureFaces:
    """The vertex pairs of the fracture ``segment`` (its ends, shape ``(2, 2)``) whose faces are
    the boundary part ``name`` of the cut particles ``p`` (``cut_triangulation``'s name)."""
    if name not in p.boundary_names:
        raise InputError(f"no boundary part {name!r} for the fracture; the parts are "
                         f"{', '.join(sorted(p.boundary_names))} (cut_triangulation names the faces)")
    a, b = np.asarray(segment, float).reshape(2, 2)
    t = (b - a) / np.linalg.norm(b - a)
    n_c = np.array([t[1], -t[0]])  # the right-hand normal of the segment
    edges = p.boundary_edges[p.boundary_tags == p.boundary_names[name]]
    length = np.linalg.norm(p.x[edges[:, 1]] - p.x[edges[:, 0]], axis=1)
    weight = np.zeros(p.num_nodes)
    np.add.at(weight, edges.ravel(), np.repeat(0.5 * length, 2))
    nodes = np.unique(edges)
    side = (p.x[nodes] - a) @ n_c
    plus, minus = nodes[side > 0], nodes[side < 0]
    h = float(p.spacing[nodes].min())
    dist, j = cKDTree(p.x[minus]).query(p.x[plus]) if minus.size else (np.full(plus.size, np.inf), None)
    if plus.size == 0 or plus.size != minus.size or np.any(dist > 1e-3 * h) or len(np.unique(j)) != plus.size:
        raise InputError(f"the faces of fracture {name!r} do not pair up ({plus.size} + and {minus.size} - "
                         "vertices); cut the particles with cut_triangulation along the whole fracture")
    minus = minus[j]
    return FractureFaces(plus=p.x[plus].copy(), minus=p.x[minus].copy(), weights=weight[plus],
                         normal=np.tile(n_c, (plus.size, 1)))


def _node_of(coordinates: np.ndarray, points: np.ndarray, what: str) -> np.ndarray:
    """The index of the node at each of ``points`` among ``coordinates`` (exact copies)."""
    dist, node = cKDTree(coordinates).query(points)
    scale = float(np.ptp(coordinates, axis=0).max())
    if np.any(dist > 1e-12 * scale):
        raise InputError(f"a fracture vertex has no {what} node at its place; mesh the cut particles themselves")
    return node


def nodal_interface(faces: FractureFaces, u_nodes: np.ndarray, p_nodes: np.ndarray) -> Interface:
    """The contact rows of ``faces`` over P1 unknowns: u interleaved per node of the
    displacement space (``u_nodes``: its nodes' coordinates in global order, shape ``(n_v, 2)``)
    and p per node of the pressure space (``p_nodes``, ``(n_q, 2)``)."""
    m = faces.num_pairs
    rows = np.r_[np.arange(m), np.arange(m)]
    up, um = _node_of(u_nodes, faces.plus, "displacement"), _node_of(u_nodes, faces.minus, "displacement")
    pp, pm = _node_of(p_nodes, faces.plus, "pressure"), _node_of(p_nodes, faces.minus, "pressure")
    n_v = len(u_nodes)
    jump = sp.csr_matrix((np.r_[np.ones(m), -np.ones(m)], (rows, np.r_[up, um])), shape=(m, n_v))
    mean = sp.csr_matrix((np.full(2 * m, 0.5), (rows, np.r_[pp, pm])), shape=(m, len(p_nodes)))
    normal = faces.normal
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    return Interface(points=faces.plus, weights=faces.weights, normal=normal, tangent=tangent,
                     jump_normal=directional_rows(jump, normal, n_v), jump_tangent=directional_rows(jump, tangent, n_v),
                     mean=mean, plus=up, minus=um)


def touching(faces: FractureFaces, vertices: np.ndarray) -> np.ndarray:
    """The elements (vertices of each, shape ``(m, 3, 2)``) with a vertex on either face, sorted indices."""
    points = np.r_[faces.plus, faces.minus]
    scale = float(np.ptp(vertices.reshape(-1, 2), axis=0).max())
    dist, _ = cKDTree(points).query(vertices.reshape(-1, 2))
    return np.flatnonzero((dist <= 1e-12 * scale).reshape(-1, 3).any(axis=1))
