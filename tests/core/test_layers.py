"""Data flows down the layers (ARCHITECTURE.md): gui -> cad -> robot/core, cli only parses
arguments. Read from the source's own import statements, lazy ones inside functions included."""

import ast
from pathlib import Path

import waferscan

PACKAGE = Path(waferscan.__file__).parent


def _module_name(path):
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports():
    """{module: {module it imports}} over the waferscan package."""
    graph = {}
    for path in PACKAGE.rglob("*.py"):
        name = _module_name(path)
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        found = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                found |= {a.name for a in node.names if a.name.startswith("waferscan")}
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[:len(base) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                elif node.module and node.module.startswith("waferscan"):
                    target = node.module
                else:
                    continue
                found.add(target)
                # "from . import roles" names a module, not a name in a package's __init__
                found |= {f"{target}.{a.name}" for a in node.names}
        graph[name] = found
    return {m: {t for t in targets if t in graph and t != m} for m, targets in graph.items()}


def test_the_graph_is_read():
    graph = _imports()
    assert "waferscan.cad.reader" in graph["waferscan.cad.document_scan"]
    assert "waferscan.core.rules" in graph["waferscan.core.scan.engines"]


def test_only_the_entry_points_import_the_command_line():
    graph = _imports()
    importers = sorted(m for m, targets in graph.items() if "waferscan.cli" in targets)
    assert importers == ["waferscan.__main__"] or importers == []


def test_lower_layers_import_no_higher_one():
    graph = _imports()
    above = {"core": ("waferscan.cad", "waferscan.gui", "waferscan.robot", "waferscan.cli"),
             "robot": ("waferscan.cad", "waferscan.gui", "waferscan.cli"),
             "cad": ("waferscan.gui", "waferscan.cli")}
    wrong = [(m, t) for m, targets in graph.items() for layer, higher in above.items()
             if m.startswith(f"waferscan.{layer}.") for t in targets if t.startswith(higher)]
    assert wrong == []


def test_no_import_cycle():
    graph = _imports()
    cycles = []

    def visit(module, path):
        for target in graph[module]:
            if target in path:
                cycles.append(path[path.index(target):] + [target])
            elif target not in done:
                visit(target, path + [target])
        done.add(module)

    done = set()
    for module in sorted(graph):
        if module not in done:
            visit(module, [module])
    # A package's __init__ importing its own modules is not a cycle of the code's layers.
    packages = {m for m in graph if (PACKAGE.parent / m.replace(".", "/") / "__init__.py").exists()}
    cycles = [c for c in cycles if not packages & set(c)]
    assert cycles == [], cycles


# core's families, bottom first (ARCHITECTURE.md): each imports only the families below it. The
# base is core's own modules (model, errors, rules, schema, recipe, mapping).
CORE_ORDER = ("base", "geometry", "sensor", "scan", "files", "sweep")


def _family(module):
    parts = module.split(".")
    if parts[:2] != ["waferscan", "core"] or len(parts) == 2:
        return None
    if len(parts) > 3 and parts[2] in CORE_ORDER:
        return parts[2]
    return "base" if len(parts) == 3 else parts[2]


def test_core_is_made_of_its_families_alone():
    modules = [m for m in _imports() if m.startswith("waferscan.core.")]
    families = {_family(m) for m in modules if m.count(".") >= 3}
    assert families <= set(CORE_ORDER), families - set(CORE_ORDER)
    # every family is a folder with a docstring saying its job, and the base holds no other module
    for family in CORE_ORDER[1:]:
        init = PACKAGE / "core" / family / "__init__.py"
        assert ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))), family
    base = sorted(p.stem for p in (PACKAGE / "core").glob("*.py") if p.stem != "__init__")
    assert base == ["errors", "mapping", "model", "recipe", "rules", "schema"]


def test_core_families_import_only_the_families_below():
    graph = _imports()
    wrong = []
    for module, targets in graph.items():
        mine = _family(module)
        if mine is None or module in ("waferscan.core", *(f"waferscan.core.{f}" for f in CORE_ORDER)):
            continue
        for target in targets:
            theirs = _family(target)
            if theirs is not None and CORE_ORDER.index(theirs) > CORE_ORDER.index(mine):
                wrong.append((module, target))
    assert wrong == []



def test_the_package_root_holds_the_command_line_the_addon_glue_and_packages():
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert loose in (["__init__.py", "addon.py", "cli.py"],
                     ["__init__.py", "__main__.py", "addon.py", "cli.py"])


# Above core (ARCHITECTURE.md, docs/contributing.md): what each package may import of ours.
MAY_IMPORT = {
    "robot": {"core", "addon"},
    "cad": {"core", "robot", "addon"},
    "plots": {"core"},  # draws what core computed, nothing of FreeCAD's
    "sweep": {"core", "cad", "plots", "addon"},
    "bench": {"core", "robot", "cad", "plots", "sweep", "host", "addon"},
    # the host link: its E87 model and HSMS side use core alone; `waferscan serve` scans the
    # layout through cad
    "host": {"core", "cad", "addon"},
}


def test_the_packages_import_only_those_below_them():
    graph = _imports()
    wrong = []
    for module, targets in graph.items():
        own = module.split(".")[1] if module.count(".") else None
        if own not in MAY_IMPORT:
            continue
        for target in targets:
            theirs = target.split(".")[1] if target.count(".") else None
            if theirs not in (own, None) and theirs not in MAY_IMPORT[own]:
                wrong.append((module, target))
    assert wrong == []
