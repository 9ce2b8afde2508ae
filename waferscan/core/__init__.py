"""The simulator's core: model, geometry, scan engines, slot mapping and file formats.

Pure Python and numpy. Nothing here imports FreeCAD, Qt or pinocchio, so it runs and is tested
anywhere.
"""
