"""WaferScan: wafer-scanning simulation for FreeCAD."""

__version__ = "0.1.0"
