"""The package's surface: names, docstrings (help() is useful), stubs that match."""
import ast
import inspect
import pathlib

import hoist


def test_public_names_and_docstrings():
    for name in hoist.__all__:
        assert hasattr(hoist, name), name
    for fn in (hoist.simulate, hoist.simulate_batch, hoist.estimate, hoist.read_log):
        doc = inspect.getdoc(fn)
        assert doc and len(doc) > 300, fn.__name__
    doc = inspect.getdoc(hoist.simulate)
    for option in ("dt", "max_step", "t_end", "modes", "initial", "method", "static_correction", "profile",
                   "Raises", "Returns"):
        assert option in doc, option
    assert "ConfigError" in hoist.Config.set.__doc__ and "Config.keys()" in hoist.Config.set.__doc__
    assert "line" in hoist.Config.from_file.__doc__


def test_stubs_name_every_public_function_with_the_same_keywords():
    stub = ast.parse((pathlib.Path(hoist.__file__).parent / "__init__.pyi").read_text())
    defs = {n.name: n for n in stub.body if isinstance(n, ast.FunctionDef)}
    classes = {n.name for n in stub.body if isinstance(n, ast.ClassDef)}
    for name in hoist.__all__:
        if name.startswith("__") or name.isupper():
            continue
        assert name in defs or name in classes, name
    for name, node in defs.items():
        real = inspect.signature(getattr(hoist, name))
        stub_names = [a.arg for a in node.args.args + node.args.kwonlyargs]
        if node.args.kwarg:
            stub_names.append(node.args.kwarg.arg)
        assert stub_names == list(real.parameters), name


def test_default_max_step_is_the_models():
    # One default substep: the C++ model's kDefaultMaxStep, the keyword
    # default of simulate and simulate_batch (hoist-sim --max-step's).
    assert hoist.DEFAULT_MAX_STEP == 0.0025
    for fn in (hoist.simulate, hoist.simulate_batch):
        assert inspect.signature(fn).parameters["max_step"].default == hoist.DEFAULT_MAX_STEP, fn.__name__
