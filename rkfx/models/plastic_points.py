"""Drucker-Prager history at a model's integration points, and a load factor on its loads.

The elastic-plastic skeleton of ``rkfx.models.unsaturated_poroelasticity`` and of its FEM
baseline (``fem_baselines.unsaturated``): each integration point keeps its committed strain,
effective stress and equivalent plastic strain; a residual evaluation returns the points'
trial stresses by the return map (``rkfx.materials.drucker_prager``) of the strain increment
from the committed state, the Jacobian takes the return's algorithmic tangent, and the
steppers' ``commit()`` makes the last trial the committed state. A ramp lambda(t) scales the
skeleton's loads (gravity), the path along which a plastic state takes its load.

Strains are Voigt (xx, yy, gamma_xy), stresses (xx, yy, zz, xy), as the law's.
"""
from collections.abc import Callable

import numpy as np

from rkfx.errors import InputError
from rkfx.materials.drucker_prager import DruckerPrager

#: The committed arrays, as checkpoints keep them.
KEYS = ("strain", "stress", "plastic_strain")


class PlasticPoints:
    """Mixin of a model whose skeleton may be Drucker-Prager (``plasticity``) and whose loads
    may follow a ramp; ``commit``, ``state`` and ``restore`` extend the base model's."""

    plasticity: DruckerPrager | None = None
    ramp: Callable[[float], float] | None = None

    def _plastic_points(self, plasticity: DruckerPrager | None, ramp, weight: str, E: float, nu: float,
                        points: int) -> None:
        """Validate and start the history of ``points`` integration points (unstressed)."""
        self.plasticity, self.ramp = plasticity, ramp
        if plasticity is None:
            return
        if not isinstance(plasticity, DruckerPrager):
            raise InputError(f"plasticity {plasticity!r} is not a DruckerPrager law")
        if weight != "full":
            raise InputError("plasticity needs weight='full': the skeleton's whole stress, from an unstressed start")
        if not np.isclose(plasticity.E, E) or not np.isclose(plasticity.nu, nu):
            raise InputError(f"the plasticity's E = {plasticity.E:g}, nu = {plasticity.nu:g} differ from the medium's "
                             f"E = {E:g}, nu = {nu:g}; give the same elastic constants")
        self._committed = (np.zeros((points, 3)), np.zeros((points, 4)), np.zeros(points))
        self._trial = None

    def _factor(self, t: float) -> float:
        """The load factor lambda(t) (1 without a ramp)."""
        if self.ramp is None:
            return 1.0
        lam = float(self.ramp(t))
        if not np.isfinite(lam):
            raise InputError(f"ramp({t:g}) = {lam!r}: the load factor must be finite")
        return lam

    def _factor_slope(self, t: float) -> float:
        """lambda'(t) by central differences (exact for a linear ramp; 0 without a ramp)."""
        if self.ramp is None:
            return 0.0
        e = 1e-6 * max(1.0, abs(t))
        return (self._factor(t + e) - self._factor(t - e)) / (2.0 * e)

    def _return_map(self, eps: np.ndarray) -> np.ndarray:
        """The trial stresses (points, 4) of the strains ``eps`` (points, 3), kept as the trial."""
        strain, stress, plastic = self._committed
        self._trial = (eps, self.plasticity.update(stress, eps - strain, plastic))
        return self._trial[1].stress

    def _return_tangent(self) -> np.ndarray:
        """d sigma / d eps of the last trial, (points, 3, 3): stress (xx, yy, xy) against strain
        (xx, yy, gamma_xy)."""
        upd = self._trial[1]
        d_lambda = np.sqrt(3.0) * (upd.plastic_strain - self._committed[2])
        return self.plasticity.algorithmic_tangent(upd.stress, upd.yielded, d_lambda)[:, [0, 1, 3], :]

    @property
    def plastic_state(self) -> tuple[np.ndarray, np.ndarray] | None:
        """With plasticity, the committed sigma'' (points, 4) [Pa] and equivalent plastic strain
        (points,) at the integration points; else ``None``."""
        return None if self.plasticity is None else self._committed[1:]

    def commit(self) -> None:
        super().commit()
        if self.plasticity is not None and self._trial is not None:
            eps, upd = self._trial
            self._committed = (eps, upd.stress, upd.plastic_strain)

    def state(self) -> dict[str, np.ndarray]:
        out = dict(super().state())
        if self.plasticity is not None:
            out.update(zip(KEYS, self._committed))
        return out

    def restore(self, arrays) -> None:
        super().restore(arrays)
        if self.plasticity is not None:
            self._committed = tuple(np.array(arrays[k]) for k in KEYS)
            self._trial = None
