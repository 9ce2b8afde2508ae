# WaferScan: run by FreeCAD at start-up (GUI and freecadcmd) with exec(), so there is no
# __file__ here. The addon's environment logic lives in waferscan/addon.py.
import waferscan.addon

waferscan.addon.add_venv_site_packages()

# Said once, at start-up: an Addon Manager install has no venv, so no pinocchio for the robot.
if not waferscan.addon.pinocchio_available():
    import FreeCAD

    FreeCAD.Console.PrintWarning("WaferScan: " + waferscan.addon.missing_pinocchio_message() + "\n")
