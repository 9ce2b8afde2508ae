"""The workbench GUI (FreeCADGui + Qt): shows results, never computes them."""
