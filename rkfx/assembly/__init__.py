"""Operators as B^T D B w products, boundary integrals and collocated conditions, the smeared strain of explicit SCNI."""
