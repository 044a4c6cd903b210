"""Exact and manufactured solutions, vectorised functions of (x, t), with references.

    kirsch         infinite plane-strain plate with a circular hole under remote uniaxial tension
    manufactured   manufactured plane-strain fields (sine field with its body force; linear patch)
"""
