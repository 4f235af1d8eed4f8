"""Issue 37's house figures of a checkout: where the compiled functions live, the largest parameter count, the
module-level mutable caches and the function-local approachsim imports (an AST count; tools/import_figures.py counts
the import circles, `duplicates` the repeated lines).

    python tools/core_figures.py [ROOT]        # ROOT: a checkout (default: this one)
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

_COMPILED = ("njit", "jit", "intrinsic")


def _decorator_name(d: ast.expr) -> str:
    f = d.func if isinstance(d, ast.Call) else d
    return getattr(f, "id", getattr(f, "attr", ""))


def _place(rel: Path) -> str:
    """The place a compiled function lives: core/, a kernels/ folder, or its file."""
    parts = rel.parts
    if parts[0] == "core":
        return "core/"
    if "kernels" in parts:
        return "/".join(parts[:parts.index("kernels") + 1]) + "/"
    return rel.as_posix()


def _n_params(n: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = n.args
    k = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)
    return k - 1 if a.args and a.args[0].arg in ("self", "cls") else k


def _is_empty_cache(v: ast.expr | None, src: str) -> bool:
    """An empty dict / list, or a (None, ...) memo tuple."""
    if isinstance(v, ast.Dict):
        return not v.keys
    if isinstance(v, ast.List):
        return not v.elts
    return isinstance(v, ast.Tuple) and (ast.get_source_segment(src, v) or "").startswith("(None")


def figures(root: Path) -> None:
    pkg = root / "approachsim"
    n_fn = n_lines = over = 0
    places: set[str] = set()
    largest = (0, "")
    caches: list[str] = []
    local = local_cmd = 0
    for f in sorted(pkg.rglob("*.py")):
        src = f.read_text(encoding="utf-8")
        rel = f.relative_to(pkg)
        tree = ast.parse(src)
        for n in tree.body:
            target = n.targets[0] if isinstance(n, ast.Assign) else n.target if isinstance(n, ast.AnnAssign) else None
            if (isinstance(target, ast.Name) and target.id.startswith("_") and target.id[1:].isupper()
                    and _is_empty_cache(n.value, src)):
                caches.append(f"{rel.as_posix()}:{target.id}")
        for n in ast.walk(tree):
            if not isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            if any(_decorator_name(d) in _COMPILED for d in n.decorator_list):
                n_fn += 1
                n_lines += n.end_lineno - n.lineno + 1
                places.add(_place(rel))
            k = _n_params(n)
            over += k > 15
            if k > largest[0]:
                largest = (k, f"{rel.as_posix()}:{n.name}")
            for m in ast.walk(n):
                if (isinstance(m, ast.ImportFrom) and (m.module or "").startswith("approachsim")) or (
                        isinstance(m, ast.Import) and any(a.name.startswith("approachsim") for a in m.names)):
                    if "commands" in rel.parts:
                        local_cmd += 1
                    else:
                        local += 1
    print(f"compiled functions (njit / intrinsic): {n_fn}, {n_lines} lines, in {len(places)} places: {sorted(places)}")
    print(f"largest parameter count: {largest[0]} ({largest[1]}); functions over 15 parameters: {over}")
    print(f"module-level empty caches named _UPPER: {len(caches)} {caches}")
    print(f"function-local approachsim imports: {local} outside commands/, {local_cmd} in commands/ (each statement "
          f"once; nested functions counted in each enclosing one)")


if __name__ == "__main__":
    figures(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1])
