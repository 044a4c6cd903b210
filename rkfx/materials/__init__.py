"""Constitutive laws: 2-D elasticity (plane strain and stress) and the compiled Mazars strain and damage law."""
