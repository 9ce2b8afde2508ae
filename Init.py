# WaferScan: run by FreeCAD at start-up (GUI and freecadcmd) with exec(), so there is no
# __file__ here. The addon's environment logic lives in waferscan/addon.py.
import waferscan.addon

waferscan.addon.add_venv_site_packages()
