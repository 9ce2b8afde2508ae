"""FreeCAD layer (App, no Gui): roles on document objects, the document reader and builder,
the document and B-rep engines, the CAD cross-check."""
