"""Exact and manufactured solutions, vectorised functions of (x, t), with references.

    kirsch         infinite plane-strain plate with a circular hole under remote uniaxial tension
    manufactured   manufactured elastic fields, plane strain and 3-D (sine fields with their body
                   forces; linear patch)
    terzaghi       1-D consolidation of a column (Fourier and short-time erfc series), general Biot
    mandel         Mandel's squeezed slab (Abousleiman et al. 1996), general Biot, S = 0 explicit
    strip_load     strip load on a drained poroelastic half-plane (Schiffman, Chen & Jordan 1969),
                   incompressible constituents, closed form in Fourier space + quadrature
    cohesive_bar   bar under tension breaking along one crack with the linear cohesive law
                   (Wei 2018, eqs. 4.7-4.9): force and crack opening against the tip displacement
    sneddon        opening of a pressurized straight crack in an unbounded plane (Sneddon 1946,
                   Wei 2018 eq. 5.37)
    wave_column    step-loaded saturated u-p column with inertia (Wei 2018 §6.4.1): Laplace domain,
                   Fourier-series inversion; the undrained rod in closed form
    cryer          Cryer's poroelastic sphere under a sudden load (Cryer 1963), general Biot:
                   residue series and Talbot inversion
    crossing       does a hydraulic fracture cross a frictional interface? Renshaw-Pollard (1995),
                   a construction after Gu-Weng (2010), Blanton's tests (Wei 2018 Table 5.1)
"""
