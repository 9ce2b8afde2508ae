"""The robot layer: kinematics from a URDF with Pinocchio. No FreeCAD here; pinocchio is
imported by ``waferscan.robot.kinematics`` only, so importing this package costs nothing."""
