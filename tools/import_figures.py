"""Import-structure figures of the package (issue 37's acceptance table): import circles among modules, two-cycles
among first-level packages, and function-local `approachsim` imports outside commands/.

    python tools/import_figures.py [-v]     # -v: list each circle, two-cycle and local import

Circles: the strongly connected components of more than one module in grimp's import graph of approachsim (every
import statement counts, function-local and TYPE_CHECKING ones included). Two-cycles: pairs of first-level packages
or modules (approachsim.nav, approachsim.memo, ...) that import each other, by any of their modules. Function-local
imports: `from approachsim... import` / `import approachsim...` statements inside a function body (ast), counted
outside approachsim/commands/ (the CLI's commands import their stage lazily on purpose). The contracts that keep the
first two at zero are import-linter's (pyproject.toml: "No import cycle ...", acyclic_siblings).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import grimp

PACKAGE = Path(__file__).resolve().parents[1] / "approachsim"


def circles(graph: grimp.ImportGraph) -> list[list[str]]:
    """Strongly connected components (Tarjan) of more than one module."""
    mods = sorted(m for m in graph.modules if m.startswith("approachsim"))
    edges = {m: sorted(x for x in graph.find_modules_directly_imported_by(m) if x.startswith("approachsim"))
             for m in mods}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(max(10000, sys.getrecursionlimit()))
    for m in mods:
        if m not in index:
            visit(m)
    return sorted(out)


def two_cycles(graph: grimp.ImportGraph) -> list[tuple[str, str]]:
    """First-level packages (or modules) of approachsim that import each other."""
    def top(m: str) -> str:
        return ".".join(m.split(".")[:2])

    pairs = set()
    for a in graph.modules:
        if not a.startswith("approachsim."):
            continue
        for b in graph.find_modules_directly_imported_by(a):
            if b.startswith("approachsim.") and top(a) != top(b):
                pairs.add((top(a), top(b)))
    return sorted({tuple(sorted(p)) for p in pairs if (p[1], p[0]) in pairs})


def local_imports() -> list[str]:
    """Function-local approachsim imports outside commands/: 'path:line: module'."""
    out = []
    for f in sorted(PACKAGE.rglob("*.py")):
        if "commands" in f.relative_to(PACKAGE).parts:
            continue
        for node in ast.walk(ast.parse(f.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for sub in ast.walk(node):
                name = None
                if isinstance(sub, ast.ImportFrom) and (sub.level or (sub.module or "").startswith("approachsim")):
                    name = "." * sub.level + (sub.module or "")
                elif isinstance(sub, ast.Import) and any(a.name.startswith("approachsim") for a in sub.names):
                    name = ", ".join(a.name for a in sub.names)
                if name is not None:
                    out.append(f"{f.relative_to(PACKAGE.parent)}:{sub.lineno}: {name}")
    return out


def main() -> int:
    verbose = "-v" in sys.argv[1:]
    graph = grimp.build_graph("approachsim")
    c, t, loc = circles(graph), two_cycles(graph), local_imports()
    print(f"import circles (module SCCs): {len(c)}")
    if verbose:
        for s in c:
            print("   ", " -> ".join(s))
    print(f"package two-cycles: {len(t)}")
    if verbose:
        for a, b in t:
            print(f"    {a} <-> {b}")
    print(f"function-local approachsim imports outside commands/: {len(loc)}")
    if verbose:
        for line in loc:
            print("   ", line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
