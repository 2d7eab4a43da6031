"""The API reference is complete: every public class, function, method and property of the
package has a docstring that names each of its parameters and shows an example, and every
example runs as written (the reference is generated from these docstrings by pdoc)."""
import doctest
import inspect

import numpy as np
import pandas as pd

import termid
import termid.plot
import termid.sklearn


def _public_members(owner):
    for name, member in vars(owner).items():
        # operators are documented on their class (a native class's slots carry Python's
        # generic text); scikit-learn's metadata-routing setters are its own
        if name.startswith("_") or name.endswith("_request"):
            continue
        yield name, member


def public_api():
    """(qualified name, object, parameter names) of everything a user calls or reads."""
    found = []
    modules = [termid, termid.plot, termid.sklearn]
    for module in modules:
        names = getattr(module, "__all__", None) or [n for n in vars(module) if not n.startswith("_")]
        for name in names:
            obj = getattr(module, name)
            if name == "__version__" or inspect.ismodule(obj):
                continue
            if getattr(obj, "__module__", "").split(".")[0] not in ("termid", "_termid"):
                continue  # imported from elsewhere (pandas, typing)
            qual = f"{module.__name__}.{name}"
            if inspect.isclass(obj):
                # a class users build names its constructor's parameters; the others are
                # made by the package (Model.load, fit)
                built = obj is termid.sklearn.TermRegressor
                found.append((qual, obj, _parameters(obj) if built else []))
                for member_name, member in _public_members(obj):
                    target = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
                    if isinstance(target, property):
                        found.append((f"{qual}.{member_name}", target, []))
                    elif callable(target) or inspect.ismethoddescriptor(target) or inspect.isgetsetdescriptor(target):
                        found.append((f"{qual}.{member_name}", getattr(obj, member_name), _parameters(target)))
            elif callable(obj):
                found.append((qual, obj, _parameters(obj)))
    return found


def _parameters(fn):
    try:
        signature = inspect.signature(fn)
    except (TypeError, ValueError):
        return []
    return [
        p.name
        for p in signature.parameters.values()
        if p.name not in ("self", "cls") and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]


def _doc(obj):
    return inspect.getdoc(obj.fget if isinstance(obj, property) else obj) or ""


def test_every_public_object_is_documented_with_parameters_and_an_example():
    missing = []
    api = public_api()
    assert len(api) > 60, len(api)
    for qual, obj, parameters in api:
        doc = _doc(obj)
        if not doc.strip():
            missing.append(f"{qual}: no docstring")
            continue
        if ">>>" not in doc:
            missing.append(f"{qual}: no example")
        for p in parameters:
            if f"``{p}``" not in doc and f"`{p}`" not in doc:
                missing.append(f"{qual}: parameter {p} not described")
    assert not missing, "\n".join(missing)


def test_every_example_in_the_reference_runs():
    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    globs = {"termid": termid, "np": np, "pd": pd}
    seen = set()
    for qual, obj, _ in public_api():
        target = obj.fget if isinstance(obj, property) else obj
        for test in finder.find(target, qual, globs=dict(globs)):
            if test.examples and id(test.docstring) not in seen:
                seen.add(id(test.docstring))
                runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0 and result.attempted > 60, result
