"""FreeCAD layer (App, no Gui): roles on document objects, the document reader and builder,
the document and B-rep engines, the CAD cross-check."""

# False in a process that ends when its command is done (the `waferscan` console script): the
# documents it opens are left to the process's end, where nothing closes them (layout_files.
# done_with). Closing one takes FreeCAD a third as long as opening it (10,000 wafers: 1.0 s
# against 2.7 s), all of it freeing memory the ending process gives back anyway. Here, not in
# layout_files, so that setting it does not import FreeCAD.
CLOSE_AFTER_USE = True
