"""The host link (SPEC §14): the layout's carriers as load ports of an equipment that a factory
host reaches over SECS/GEM (HSMS, GEM, SEMI E87).

``e87`` keeps each port's carrier and slot-map status (pure Python); ``ids`` reads the tool's
SECS/GEM identifiers; ``equipment`` speaks HSMS through the ``secsgem`` library; ``server`` runs
the link for ``waferscan serve``. Nothing here imports FreeCAD or Qt: the slot maps come from a
scan function the caller gives.
"""
