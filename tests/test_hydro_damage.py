"""Damaged particles' u-p fields (chapter 5), band widths, and essential conditions on regions."""
import numpy as np
import pytest

from rkfx.approximation.shape_functions import rk_approximation
from rkfx.assembly.boundary import boundary_quadrature, collocation, part_nodes, part_points
from rkfx.conditions import Pressure, Region
from rkfx.errors import InputError
from rkfx.fracture.damage import band_widths, cell_geometry
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import graded
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.hydro_damage import CrackBands, crack_apertures, crack_bands, damaged_fields

XS = np.linspace(0.0, 1.0, 11)


def test_band_width_of_grid_cells_is_the_cell_size_across_the_crack():
    d = grid_domains(XS, np.linspace(0.0, 0.5, 6))
    n = len(d.area)
    horizontal = crack_bands(d, np.tile([0.0, 1.0], (n, 1)))  # crack along x: L_s = V / A = h_y
    inner = np.flatnonzero(np.isclose(d.area, 0.01))
    np.testing.assert_allclose(horizontal.width[inner], 0.1)
    diagonal = band_widths(cell_geometry(d), d.area, inner, np.tile([1.0, 1.0], (len(inner), 1)) / np.sqrt(2))
    np.testing.assert_allclose(diagonal, 0.01 / (0.1 * np.sqrt(2)))  # the chord is the cell's diagonal


def test_aperture_is_the_band_strain_times_its_width():
    bands = CrackBands(np.tile([0.0, 1.0], (3, 1)), np.full(3, 0.1))
    strain = np.array([[0.0, 2e-3, 0.0], [0.0, -1e-3, 0.0], [5e-3, 2e-3, 0.0]])
    np.testing.assert_allclose(crack_apertures(np.array([1.0, 1.0, 0.5]), bands, strain), [2e-4, 0.0, 1e-4])


def test_damaged_fields_degrade_stiffness_and_raise_biot_coefficient():
    el = ElasticMaterial(1e10, 0.2)
    d = np.array([0.0, 0.5, 1.0])
    f = damaged_fields(el, d, residual=1e-3, grain_modulus=5e10, porosity=0.2, fluid_modulus=2e9)
    np.testing.assert_allclose(f.D[:, 0, 0] / el.D()[0, 0], [1.0, 0.5, 1e-3])
    k_ratio = el.bulk_modulus / 5e10
    np.testing.assert_allclose(f.alpha, [1 - k_ratio, 1 - 0.5 * k_ratio, 1.0])
    np.testing.assert_allclose(f.S, 0.2 / 2e9 + (f.alpha - 0.2) / 5e10)
    assert f.k is None


def test_damaged_fields_crack_permeability_along_the_crack_only():
    el = ElasticMaterial(1e10, 0.2)
    bands = CrackBands(np.tile([0.0, 1.0], (2, 1)), np.full(2, 0.01))
    strain = np.array([[0.0, 1e-2, 0.0], [0.0, 1e-2, 0.0]])
    f = damaged_fields(el, np.array([0.0, 1.0]), mobility=1e-12, bands=bands, strain=strain, viscosity=1e-3)
    w = 0.01 * 1e-2
    np.testing.assert_allclose(f.k[0], 1e-12 * np.eye(2))
    np.testing.assert_allclose(f.k[1], np.diag([w**3 / (12e-3 * 0.01), 1e-12]))


@pytest.mark.parametrize("kwargs, word", [({"residual": 0.0}, "residual"), ({"grain_modulus": 5e10, "porosity": 0.2},
                                          "fluid_modulus"), ({"bands": CrackBands(np.array([[0.0, 1.0]] * 3),
                                                                                  np.ones(3))}, "mobility")])
def test_damaged_fields_bad_input(kwargs, word):
    with pytest.raises(InputError, match=word):
        damaged_fields(ElasticMaterial(1.0, 0.2), np.zeros(3), **kwargs)
    with pytest.raises(InputError, match="damage"):
        damaged_fields(ElasticMaterial(1.0, 0.2), np.array([0.0, 1.5]))


def test_region_prescribes_interior_particles():
    p = graded(XS, XS)
    centre = Region(lambda x: np.hypot(x[:, 0] - 0.5, x[:, 1] - 0.5) < 0.12, "centre")
    nodes = part_nodes(p, centre)
    assert len(nodes) == 5 and not np.isin(nodes, p.boundary_nodes()).any()
    rk = rk_approximation(p.x, p.spacing, 1.5)
    col = collocation(p, rk, [([Pressure(centre, 3.0)], 0, 1)], p.num_nodes)
    assert col.G.shape == (5, p.num_nodes)
    np.testing.assert_allclose(col.values(p.x), 3.0)
    with pytest.raises(InputError, match="natural conditions"):
        part_points(p, boundary_quadrature(p, nodal_domains(p), rk), centre)
    with pytest.raises(InputError, match="widen the region"):
        part_nodes(p, Region(lambda x: x[:, 0] > 2.0, "nowhere"))
    with pytest.raises(InputError, match="not callable"):
        Region(3.0)
