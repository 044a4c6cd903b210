"""The drained moduli a reference solution needs, from rkfx's one elasticity."""
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
