"""Exact and manufactured solutions, vectorised functions of (x, t), with references.

    kirsch   infinite plane-strain plate with a circular hole under remote uniaxial tension
"""
