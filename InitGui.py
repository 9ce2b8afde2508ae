# WaferScan: run by FreeCAD's GUI at start-up with exec() inside a function. Names bound at the
# top of this file are not visible inside the class's methods (FreeCAD 0.20 quirk), so the
# methods import what they use themselves.
import FreeCADGui
import waferscan.addon


class WaferScanWorkbench(FreeCADGui.Workbench):
    """The WaferScan workbench: wafer-scanning simulation in a CAD assembly."""

    MenuText = "WaferScan"
    ToolTip = "Simulate wafer scanning (wafer mapping) with a through-beam sensor"

    def Initialize(self):
        """Called once, when the workbench is first activated."""
        import waferscan.gui.commands

        toolbar, menu = waferscan.gui.commands.register()
        self.appendToolbar("WaferScan", toolbar)
        self.appendMenu("&WaferScan", menu)

    def GetClassName(self):
        return "Gui::PythonWorkbench"


WaferScanWorkbench.Icon = waferscan.addon.icon_path()
FreeCADGui.addWorkbench(WaferScanWorkbench())
# The preferences page is there before the workbench is first activated, as FreeCAD's own are;
# its icon is found by name (preferences-waferscan.svg) on the icon path.
FreeCADGui.addIconPath(waferscan.addon.icon_path(""))
import waferscan.gui.preferences  # noqa: E402
waferscan.gui.preferences.register()
# WaferScan's objects get their roles' icons, also in documents built headless and opened here.
import waferscan.gui.view_providers  # noqa: E402
waferscan.gui.view_providers.install()
