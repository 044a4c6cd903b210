"""What runs leave for other tools: particle fields through time for ParaView (``paraview``)."""
