"""How the 3D view looks while a scan plays (``ScanAppearance``), all of it put back when the
scan ends: the carriers see-through, the beam drawn thick (WaferScan's own beam) or drawn over a
user's scanner (``BeamOverlay``), green while clear and red while blocked, the wafers it meets
highlighted, and the closed solids drawn without their back faces (``BackFaces``). View
properties and scene-graph nodes only: the document is not changed."""

from __future__ import annotations

__all__ = ["ScanAppearance", "BeamOverlay", "BackFaces", "opaque_closed_solids",
           "see_through_objects", "is_own_beam", "BEAM_CLEAR", "BEAM_BLOCKED", "WAFER_HIT"]

BEAM_CLEAR, BEAM_BLOCKED = (0.1, 0.6, 0.1), (0.9, 0.1, 0.1)
WAFER_HIT = (0.95, 0.55, 0.1)


class ScanAppearance:
    """The 3D view's look while ``result``'s scan of ``doc`` plays (``scene``: the document's
    DocumentScene), set up when made. ``show_beam(colour)`` colours the beam, ``light(names)``
    highlights those wafers (``lit`` names the ones highlighted now), ``undo_steps()`` puts the
    rest back."""

    def __init__(self, doc, scene, result):
        self.beam = scene.scanner().obj
        # Each wafer of the result by its name, as the scene walk found it: the object it shows
        # through links (the one whose colour the 3D view draws).
        self.wafers = {wafer.name: instance.target
                       for wafer, instance in zip(result.layout.wafers, scene.wafers)}
        self.colours = {name: tuple(w.ViewObject.ShapeColor[:3])
                        for name, w in self.wafers.items() if w.ViewObject}
        self.lit = ()
        self._beam_colour = None
        # While it runs, the carriers are see-through and the beam drawn thick: the beam lies
        # inside the carrier, behind its walls. Each property changed, with its value before.
        self.saved_properties = []
        changes = [(obj, "Transparency", 70) for obj in see_through_objects(scene)]
        # WaferScan's own scanner is the beam rod itself; a user's scanner is a solid (a fork)
        # that keeps its look, and the beam is drawn over it in the 3D view.
        self.overlay = None
        if is_own_beam(self.beam):
            changes += [(self.beam, "LineWidth", 4.0), (self.beam, "ShapeColor", None),
                        (self.beam, "LineColor", None)]
        elif self.beam.ViewObject is not None:
            self.overlay = BeamOverlay(self.beam)
        for obj, prop, value in changes:
            view = obj.ViewObject
            # hasattr: FreeCAD 1.0 lists ShapeAppearance, not ShapeColor, among the properties
            # (the beam's colour was not put back after a scan there).
            if view is not None and hasattr(view, prop):
                self.saved_properties.append((view, prop, getattr(view, prop)))
                if value is not None:
                    setattr(view, prop, value)
        # The opaque closed solids drawn without their back faces while it runs (nothing
        # changes on screen; see BackFaces).
        try:
            self.back_faces = BackFaces.culled(opaque_closed_solids(doc))
        except Exception:  # a view provider without usable nodes: everything drawn as it is
            self.back_faces = BackFaces([])

    def show_beam(self, colour):
        """Draw the beam in ``colour`` (an RGB triple, 0 to 1)."""
        # Only on a change: setting a colour, even the same one, makes Coin redraw the beam.
        if colour == self._beam_colour:
            return
        self._beam_colour = colour
        if self.overlay is not None:
            self.overlay.set_colour(colour)
        elif self.beam.ViewObject is not None:
            self.beam.ViewObject.ShapeColor = colour
            self.beam.ViewObject.LineColor = colour

    def light(self, names):
        """Highlight the wafers named (the others in their own colours again)."""
        if names == self.lit:
            return
        for name in self.lit:
            if name in self.wafers and name in self.colours:
                self.wafers[name].ViewObject.ShapeColor = self.colours[name]
        for name in names:
            if name in self.wafers and self.wafers[name].ViewObject:
                self.wafers[name].ViewObject.ShapeColor = WAFER_HIT
        self.lit = names

    def release(self):
        """The document is being closed: nothing is put back (it all goes with it); only the
        scene-graph nodes held are let go."""
        self.back_faces.release()
        self.overlay = None
        self.saved_properties = []

    def undo_steps(self):
        """The calls that put the view back, in order (the wafers' colours: ``light(())``):
        each to be made on its own, so that one that fails (its object deleted meanwhile)
        leaves the others."""
        steps = [self.back_faces.restore]
        if self.overlay is not None:
            steps.append(self.overlay.remove)
        steps += [lambda v=view, p=prop, x=value: setattr(v, p, x)
                  for view, prop, value in self.saved_properties]
        return steps


def is_own_beam(obj):
    """Whether the scanner object is WaferScan's own beam (drawn as the beam itself), not a
    user's solid."""
    from ..cad.features import ScannerBeam

    return isinstance(getattr(obj.getLinkedObject(True), "Proxy", None), ScannerBeam)


def see_through_objects(scene):
    """What turns see-through while the scan runs: each carrier, or, for a carrier that is a
    container (a user's App::Part or an imported link group), the shapes inside it; wafers and
    the scanner inside it stay as they are."""
    from ..cad import roles

    found, seen = [], set()
    stack = [instance.obj for instance in scene.carriers]
    while stack:
        obj = stack.pop()
        if obj.Name in seen:
            continue
        seen.add(obj.Name)
        view = obj.ViewObject
        if view is not None and "Transparency" in view.PropertiesList:
            found.append(obj)
            continue
        for sub in obj.getSubObjects():
            child = obj.getSubObject(sub, retType=1)
            if child is not None and roles.role_of(child) not in (roles.WAFER, roles.SCANNER):
                stack.append(child)
    return found


class BeamOverlay:
    """The beam from a user's scanner's emitter to its receiver, drawn into the scanner's own
    scene-graph node, so that it moves with the scanner; not a document object, so nothing
    enters the document or its undo history."""

    def __init__(self, obj):
        from pivy import coin

        from ..cad import roles

        role_object = roles.role_holder(obj)
        self.root = obj.ViewObject.RootNode
        self.node = coin.SoSeparator()
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        self.colour = coin.SoBaseColor()
        style = coin.SoDrawStyle()
        style.lineWidth = 4
        points = coin.SoCoordinate3()
        points.point.setValues(0, 2, [tuple(role_object.Emitter), tuple(role_object.Receiver)])
        line = coin.SoLineSet()
        line.numVertices.setValue(2)
        for node in (light, self.colour, style, points, line):
            self.node.addChild(node)
        self.root.addChild(self.node)
        self.set_colour(BEAM_CLEAR)

    def set_colour(self, rgb):
        self.colour.rgb.setValue(*rgb)

    def remove(self):
        self.root.removeChild(self.node)


# Part's primitives, always one closed solid facing out (wafers built before WaferScan gave
# them its own Python feature are Part::Cylinders).
CLOSED_PRIMITIVES = ("Part::Box", "Part::Cylinder", "Part::Sphere", "Part::Cone", "Part::Torus")


def _closed_by_make(obj):
    """Whether ``obj`` is one closed solid by the way it is made: one of Part's primitives, or
    a flat wafer WaferScan built (``features.Wafer``, a cylinder)."""
    from ..cad.features import Wafer

    return obj.TypeId in CLOSED_PRIMITIVES or type(getattr(obj, "Proxy", None)) is Wafer


def opaque_closed_solids(doc):
    """The shapes of ``doc`` shown opaque whose every face bounds a closed solid of positive
    volume (no loose face, no open shell, not turned inside out): from outside, only their
    front faces can be seen. The see-through ones are left out (set before: the carriers while
    the scan runs), and containers (App::Part), whose view holds their children's."""
    found = []
    for obj in doc.Objects:
        view = getattr(obj, "ViewObject", None)
        if view is None or not view.Visibility or not obj.isDerivedFrom("Part::Feature"):
            continue
        if obj.hasExtension("App::GroupExtension"):
            # A container that is a shape too (a PartDesign Body): its view holds its
            # features' views, each with shape hints of its own; they are judged alone.
            continue
        if getattr(view, "Transparency", 0):
            continue
        try:
            shape = obj.Shape
            if _closed_by_make(obj):  # a wafer: checking costs ~0.09 ms each
                closed = not shape.isNull()
            else:
                solids = shape.Solids
                closed = bool(solids) and \
                    len(shape.Faces) == sum(len(s.Faces) for s in solids) and \
                    all(s.Volume > 0 and all(shell.isClosed() for shell in s.Shells)
                        for s in solids)
        except Exception:  # a shape OpenCASCADE cannot check: drawn as it is
            closed = False
        if closed:
            found.append(obj)
    return found


class BackFaces:
    """Back faces of closed solids left undrawn (culled) in the 3D view, and put back.

    FreeCAD draws every face from both sides (its shape hints leave the shape type unknown),
    so each solid's far side is rasterised too and then hidden by its near side: with software
    rendering (Mesa llvmpipe) every pixel costs. The stacked wafers' undersides and the robot's
    far sides were ~0.75 ms of a 15.6 ms frame of Run scan's animation in the bench's view.
    A closed, outward-facing solid seen from outside shows its front faces only, so the image
    is the same pixel for pixel; what the user would see differently is only the inside of a
    solid with the camera in it. Set in the view's own shape-hints nodes (not a document or
    preference change), for the animation's time."""

    def __init__(self, saved):
        self.saved = saved  # [(shape hints node, vertex ordering, shape type)]

    @classmethod
    def culled(cls, objects):
        from pivy import coin

        saved = []
        for obj in objects:
            search = coin.SoSearchAction()
            search.setType(coin.SoShapeHints.getClassTypeId())
            search.setInterest(coin.SoSearchAction.ALL)
            search.setSearchingAll(True)  # every display mode's, not only the shown one's
            search.apply(obj.ViewObject.RootNode)
            paths = search.getPaths()
            # All saved before any is set: a node met twice (shared by display modes) keeps
            # its own values to go back to.
            saved += [(hints, hints.vertexOrdering.getValue(), hints.shapeType.getValue())
                      for hints in (paths[index].getTail() for index in
                                    range(paths.getLength()))]
        for hints, _, _ in saved:
            # Held: an object deleted while the animation runs (its view provider and nodes
            # with it) must not leave restore() writing into freed nodes (FreeCAD crashed).
            hints.ref()
            # Solid, its faces counter-clockwise seen from outside (FreeCAD turns a reversed
            # face's triangles to face out): Coin culls the back faces.
            hints.vertexOrdering = coin.SoShapeHints.COUNTERCLOCKWISE
            hints.shapeType = coin.SoShapeHints.SOLID
        return cls(saved)

    def restore(self):
        """Draw both sides again, as FreeCAD had them."""
        for hints, ordering, shape_type in reversed(self.saved):
            hints.vertexOrdering = ordering
            hints.shapeType = shape_type
        self.release()

    def release(self):
        """Let go of the nodes held, as they are (once)."""
        saved, self.saved = self.saved, []
        for hints, _, _ in saved:
            hints.unref()
