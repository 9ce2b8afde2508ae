"""FreeCAD for the CAD tests: its Python library folder on sys.path. No skip when FreeCAD is
missing: the set-up installs it, so its absence is a failure."""

import sys

FREECAD_LIB = "/usr/lib/freecad-python3/lib"
if FREECAD_LIB not in sys.path:
    sys.path.append(FREECAD_LIB)
