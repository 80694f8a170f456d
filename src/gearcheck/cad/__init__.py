"""CAD adapter: the only package that imports cadquery/OCP. Numpy profiles in, B-rep solids out;
meshes come out of :mod:`gearcheck.cad.mesh` as plain numpy arrays."""
