"""The drained (and undrained) moduli a reference solution needs, from rkfx's one elasticity."""
import numpy as np

from rkfx.materials.elasticity import ElasticMaterial


class DrainedModuli:
    """G, K and K_v of a solution whose fields include ``E`` [Pa] and ``nu`` [-]."""

    E: float
    nu: float

    @property
    def G(self) -> float:
        """Shear modulus E / (2 (1 + nu)) [Pa]."""
        return ElasticMaterial(self.E, self.nu).shear_modulus

    @property
    def K(self) -> float:
        """Drained bulk modulus E / (3 (1 - 2 nu)) [Pa]."""
        return ElasticMaterial(self.E, self.nu).bulk_modulus

    @property
    def K_v(self) -> float:
        """Drained constrained (oedometric) modulus K + 4G/3 = lambda + 2G [Pa]."""
        return ElasticMaterial(self.E, self.nu).constrained_modulus


class BiotModuli(DrainedModuli):
    """The undrained moduli and the consolidation coefficient of a solution whose fields also
    include the mobility ``k`` [m^2/(Pa s)], the Biot coefficient ``alpha`` [-] and the storage
    coefficient ``S`` = 1/M [1/Pa] (0: incompressible constituents)."""

    k: float
    alpha: float
    S: float

    @property
    def K_u(self) -> float:
        """Undrained bulk modulus K + alpha^2/S [Pa]; inf for S = 0."""
        return np.inf if self.S == 0.0 else self.K + self.alpha**2 / self.S

    @property
    def B(self) -> float:
        """Skempton's coefficient alpha M / K_u = alpha / (alpha^2 + S K) [-]; 1/alpha at S = 0."""
        return self.alpha / (self.alpha**2 + self.S * self.K)

    @property
    def nu_u(self) -> float:
        """Undrained Poisson's ratio (3 K_u - 2G) / (2 (3 K_u + G)) [-]; exactly 1/2 for S = 0."""
        if self.S == 0.0:
            return 0.5
        w = self.alpha**2 + self.S * self.K  # = S K_u
        return (3.0 * w - 2.0 * self.S * self.G) / (2.0 * (3.0 * w + self.S * self.G))

    @property
    def c(self) -> float:
        """Consolidation coefficient k K_v / (alpha^2 + S K_v) [m^2/s] (PoroMaterial's c_v)."""
        return self.k * self.K_v / (self.alpha**2 + self.S * self.K_v)
