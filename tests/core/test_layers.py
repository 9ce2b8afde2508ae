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
    assert "waferscan.core.rules" in graph["waferscan.core.engines"]


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
