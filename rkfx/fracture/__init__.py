"""The damage particle method: energy-regularized damage on nodal domains, crack normals and chords, crack tracking."""
