"""Collision sweeps (python-fcl): meshes and poses in, clearances and contact poses out."""
