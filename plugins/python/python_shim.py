# SPDX-License-Identifier: MIT
# The Python half of the bridge (python_bridge.cpp): reads a Python plugin's table from
# its source without running it, imports the module when the first instance is made,
# makes instances and calls them. Compiled into the bridge as
# text (it runs in the embedded interpreter as module `_binocle_bridge`), so that the
# rules of a Python plugin's class live in one place that Python programmers can read.
import ast
import importlib.util
import os
import sys
import traceback

KINDS = ("matcher", "evaluator")
TABLE = ("name", "kind", "version", "description", "settings")
DTYPES = {1: "uint8", 2: "uint16", 4: "float32"}  # bytes per channel value -> dtype
# Setting types: the YAML words of binocle_param_desc's types (BINOCLE_PARAM_*).
TYPES = {"bool": 1, "int": 2, "float": 3, "string": 4, "enum": 5, "path": 6, "yaml": 7,
         "int_list": 8, "float_list": 9}
KEYS = {"name", "type", "default", "min", "max", "odd", "multiple_of", "choices", "unit", "help", "limit"}
FLAG_REQUIRED, FLAG_ODD, FLAG_HAS_MIN, FLAG_HAS_MAX, FLAG_LIMIT = 1, 2, 4, 8, 16


class PluginDefinitionError(Exception):
    """The module's class breaks a rule of Python plugins (sdk/README.md)."""


def _yaml_text(value):
    """A default as the YAML text a C plugin's table would hold."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml_text(v) for v in value) + "]"
    if isinstance(value, float):
        return repr(value)
    return str(value)


class Declared:
    """The class as its source declares it: the table's attributes (literals) and the
    names of its methods, read without running the module."""


def read_table(path, name):
    """The class that `binocle_plugin = <class>` names, read from the source's syntax
    tree: opening a plugin (binocle plugins, view, experiment) runs none of its code."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), path)
    target = None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "binocle_plugin" for t in node.targets):
            if not isinstance(node.value, ast.Name):
                raise PluginDefinitionError(f"{path}:{node.lineno}: binocle_plugin must name a class of this file")
            target = node.value.id
    if target is None:
        raise PluginDefinitionError("the module has no line 'binocle_plugin = <class>' (the plugin's class)")
    classes = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == target]
    if not classes:
        raise PluginDefinitionError(f"binocle_plugin = {target}: no class {target} at the top of this file")
    declared = Declared()
    for node in classes[-1].body:
        if isinstance(node, ast.FunctionDef):
            setattr(declared, node.name, len)  # a callable stands for the method
        elif isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name) \
                and node.targets[0].id in TABLE:
            try:
                setattr(declared, node.targets[0].id, ast.literal_eval(node.value))
            except ValueError:
                raise PluginDefinitionError(f"{path}:{node.lineno}: {node.targets[0].id} must be a literal (the table "
                                            "is read without running the module)") from None
    return declared


def load(path, name):
    """Imports the module at `path` and returns its plugin class (module attribute
    `binocle_plugin`)."""
    folder = os.path.dirname(path)
    if folder not in sys.path:
        sys.path.append(folder)
    spec = importlib.util.spec_from_file_location("binocle_" + name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    cls = getattr(module, "binocle_plugin", None)
    if cls is None:
        raise PluginDefinitionError("the module has no attribute 'binocle_plugin' (set it to the plugin's class)")
    return cls


def _setting(i, s):
    if not isinstance(s, dict):
        raise PluginDefinitionError(f"settings[{i}] is a {type(s).__name__}, expected a dict")
    unknown = sorted(set(s) - KEYS)
    if unknown:
        raise PluginDefinitionError(f"settings[{i}] has unknown keys {unknown} (expected some of {sorted(KEYS)})")
    name = s.get("name")
    if not isinstance(name, str):
        raise PluginDefinitionError(f"settings[{i}] has no 'name' string")
    kind = s.get("type")
    if kind not in TYPES:
        raise PluginDefinitionError(f"setting '{name}': type {kind!r} is not one of {', '.join(TYPES)}")
    flags = 0
    default = None
    if "default" in s:
        default = _yaml_text(s["default"])
    else:
        flags |= FLAG_REQUIRED
    lo, hi = s.get("min"), s.get("max")
    if lo is not None:
        flags |= FLAG_HAS_MIN
    if hi is not None:
        flags |= FLAG_HAS_MAX
    if s.get("odd"):
        flags |= FLAG_ODD
    if s.get("limit"):
        flags |= FLAG_LIMIT
    choices = s.get("choices")
    if choices is not None:
        if not all(isinstance(c, str) for c in choices):
            raise PluginDefinitionError(f"setting '{name}': choices must be strings")
        choices = "|".join(choices)
    return (name, TYPES[kind], flags, default, float(lo or 0), float(hi or 0), int(s.get("multiple_of", 0)),
            choices, str(s.get("unit", "")), str(s.get("help", "")))


def describe(cls, name):
    """(kind, version, description, settings as tuples of binocle_param_desc's fields)."""
    declared = getattr(cls, "name", name)
    if declared != name:
        raise PluginDefinitionError(f"the class declares name '{declared}' but its file is binocle_{name}.py")
    kind = getattr(cls, "kind", "matcher")
    if kind not in KINDS:
        raise PluginDefinitionError(f"kind {kind!r} is not one of {', '.join(KINDS)}")
    for attribute in ("version", "description"):
        if not isinstance(getattr(cls, attribute, None), str):
            raise PluginDefinitionError(f"the class has no '{attribute}' string")
    method = "compute(left, right)" if kind == "matcher" else "evaluate(frame)"
    if not callable(getattr(cls, method.split("(")[0], None)):
        raise PluginDefinitionError(f"the class of a {kind} has no {method} method")
    settings = getattr(cls, "settings", [])
    return kind, cls.version, cls.description, [_setting(i, s) for i, s in enumerate(settings)]


def _list(text, kind):
    inner = text.strip()[1:-1].strip()
    return [kind(v) for v in inner.split(",")] if inner else []


def create(cls, values, types):
    """An instance, given its checked settings by name (lists as their YAML text)."""
    for key, code in types.items():
        if code == TYPES["int_list"]:
            values[key] = _list(values[key], int)
        elif code == TYPES["float_list"]:
            values[key] = _list(values[key], float)
    return cls(values)


def image(data, height, width, channels, item=1, bgr=False):
    """A numpy view on the bytes the bridge copied (Python owns them: keep it if you
    like); a BGR image as a view in RGB order (channels reversed, no copy)."""
    import numpy
    array = numpy.frombuffer(data, dtype=DTYPES[item])
    array = array.reshape((height, width) if channels == 1 else (height, width, channels))
    return array[:, :, ::-1] if bgr else array


class Frame:
    """What an evaluator's evaluate(frame) receives (see sdk/README.md)."""

    def __repr__(self):
        return "Frame(" + ", ".join(sorted(vars(self))) + ")"


def frame(fields):
    f = Frame()
    for key, value in fields.items():
        setattr(f, key, value)
    return f


def figures(result):
    """evaluate's or finish's result as [(name, value, unit)]: a dict name -> value or
    (value, unit), or None."""
    if result is None:
        return []
    if not isinstance(result, dict):
        raise TypeError(f"returned a {type(result).__name__}; expected a dict of figures (name -> value or (value, unit))")
    out = []
    for name, value in result.items():
        unit = ""
        if isinstance(value, tuple):
            value, unit = value
        out.append((str(name), float(value), str(unit)))
    return out


def disparity_range(instance):
    method = getattr(instance, "disparity_range", None)
    if method is None:
        return (0, 0)
    lo, count = method()
    return (int(lo), int(count))


def dtype_of(result):
    """How a wrong result is named in an error."""
    dtype = getattr(result, "dtype", None)
    shape = getattr(result, "shape", None)
    if dtype is None:
        return type(result).__name__
    return f"numpy array of dtype {dtype}, shape {tuple(shape) if shape is not None else '?'}"


SHIM = "<binocle python bridge>"  # this file's name in tracebacks (python_bridge.cpp compiles it so)


def explain(error):
    """'ValueError: message (at file.py:12 in compute)': the innermost frame outside this
    shim; a syntax error at its own file, line and column."""
    if isinstance(error, SyntaxError) and error.filename:
        where = f"{error.filename}:{error.lineno}" + (f":{error.offset}" if error.offset else "")
        return f"{type(error).__name__}: {error.msg} (at {where})"
    text = f"{type(error).__name__}: {error}"
    frames = [f for f in traceback.extract_tb(error.__traceback__) if f.filename != SHIM]
    if frames:
        last = frames[-1]
        text += f" (at {last.filename}:{last.lineno} in {last.name})"
    return text
