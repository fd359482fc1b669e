"""The type stub (lensfield/__init__.pyi) names what the module has, with the
same parameters, and everything public has a docstring."""
import ast
import inspect
from pathlib import Path


def _stub():
    import lensfield
    tree = ast.parse((Path(lensfield.__file__).parent / "__init__.pyi").read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            out[node.name] = node
        elif isinstance(node, ast.ClassDef):
            out[node.name] = node
            for sub in node.body:
                if isinstance(sub, ast.FunctionDef):
                    out[f"{node.name}.{sub.name}"] = sub  # the last overload wins: the full one
    return out


def _params(node):
    a = node.args
    return [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg not in ("self", "cls")]


def test_stub_matches_module(lf):
    stub = _stub()
    for name in lf.__all__:
        if name != "__version__":
            assert name in stub, name
            assert getattr(lf, name).__doc__, name
    for name, node in stub.items():
        if not isinstance(node, ast.FunctionDef) or name.split(".")[-1].startswith("__"):
            continue
        obj = lf
        for part in name.split("."):
            obj = getattr(obj, part)
        if isinstance(obj, property):
            continue
        real = [p for p in inspect.signature(obj).parameters if p not in ("self", "cls")]
        if name == "open":  # layout keywords come in **layout
            assert set(_params(node)) - {"path", "white", "allow_nonfinite"} == set(lf._LAYOUT)
            continue
        assert real == _params(node), (name, real, _params(node))
        assert obj.__doc__, name
