"""gearcheck: parameter file → involute CAD (STEP/STL) → FCL interference sweep → report."""

__version__ = "0.1.0"
