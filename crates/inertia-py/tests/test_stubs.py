"""The type stubs describe the package: every public name, and the parameters of each
public function and method."""

import ast
import inspect
import pathlib

import inertia

STUB = pathlib.Path(inertia.__file__).with_name("__init__.pyi")


def stub_tree():
    return ast.parse(STUB.read_text(encoding="utf-8"))


def stub_functions():
    out = {}
    for node in stub_tree().body:
        if isinstance(node, ast.FunctionDef):
            out[node.name] = node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    out.setdefault(f"{node.name}.{item.name}", item)
    return out


def params(node: ast.FunctionDef):
    a = node.args
    names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    if a.vararg:
        names.append("*" + a.vararg.arg)
    if a.kwarg:
        names.append("**" + a.kwarg.arg)
    return [n for n in names if n not in ("self", "cls")]


def real_params(f):
    out = []
    for p in inspect.signature(f).parameters.values():
        if p.kind is p.VAR_POSITIONAL:
            out.append("*" + p.name)
        elif p.kind is p.VAR_KEYWORD:
            out.append("**" + p.name)
        elif p.name not in ("self", "cls"):
            out.append(p.name)
    return out


def test_every_public_name_is_in_the_stub():
    names = {n.name for n in stub_tree().body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    names |= {t.id for n in stub_tree().body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    assert set(inertia.__all__) - names == set()


def test_signatures_match():
    stubs = stub_functions()
    checked = 0
    for name in inertia.__all__:
        obj = getattr(inertia, name)
        if inspect.isfunction(obj):
            assert params(stubs[name]) == real_params(obj), name
            checked += 1
        elif inspect.isclass(obj) and not issubclass(obj, BaseException):
            for meth, f in vars(obj).items():
                if meth.startswith("_") and meth != "__init__":
                    continue
                f = f.__func__ if isinstance(f, classmethod) else f
                if inspect.isfunction(f) and f"{name}.{meth}" in stubs:
                    assert params(stubs[f"{name}.{meth}"]) == real_params(f), f"{name}.{meth}"
                    checked += 1
    assert checked >= 8
