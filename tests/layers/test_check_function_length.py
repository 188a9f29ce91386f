# SPDX-License-Identifier: MIT
# scripts/check-function-length.sh on planted trees: it names every function over the limit
# (file:line, the name, the length) and only those; comments, literals, preprocessor
# lines and the braces of classes, namespaces, enums and tables never fool it.
import os
import subprocess
import textwrap

import pytest

SOURCE_DIR = os.environ.get("BINOCLE_SOURCE_DIR",
                            os.path.normpath(os.path.join(os.path.dirname(__file__), "..", "..")))
SCRIPT = os.path.join(SOURCE_DIR, "scripts", "check-function-length.sh")


def check(root, *args):
    r = subprocess.run(["bash", SCRIPT, str(root), *args], capture_output=True, text=True, timeout=60)
    assert r.returncode in (0, 1), r.stdout + r.stderr
    return r.returncode, r.stdout


def plant(root, rel, text):
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text).lstrip("\n"))


def body(lines, indent="    "):
    """Statements filling `lines` lines."""
    return "".join(f"{indent}x += {k};\n" for k in range(lines))


def function(name, lines, signature=None):
    """A definition spanning exactly `lines` lines, signature to closing brace."""
    signature = signature or f"int {name}(int x)"
    return f"{signature} {{\n" + body(lines - 3 - signature.count("\n")) + "    return x;\n}\n"


@pytest.fixture
def tree(tmp_path):
    (tmp_path / "framework").mkdir()
    return tmp_path


def test_101_lines_fail_naming_the_function(tree):
    plant(tree, "framework/core/a.cpp", "// SPDX\n#include <x>\n\n" + function("tooLong", 101)
          + function("fine", 100))
    rc, out = check(tree)
    assert rc == 1
    assert "framework/core/a.cpp:4: tooLong: 101 lines (lines 4-104), over 100" in out
    assert "fine" not in out
    assert "1 problem(s)" in out


def test_100_lines_pass(tree):
    plant(tree, "framework/core/a.cpp", function("exactly", 100))
    rc, out = check(tree)
    assert rc == 0, out
    assert "ok: 1 functions in 1 files" in out


def test_max_option(tree):
    plant(tree, "framework/core/a.cpp", function("f", 30))
    assert check(tree, "--max", "30")[0] == 0
    rc, out = check(tree, "--max", "29")
    assert rc == 1 and "a.cpp:1: f: 30 lines" in out


def test_bad_arguments_are_named(tree):
    r = subprocess.run(["bash", SCRIPT, str(tree), "--max", "ten"], capture_output=True, text=True)
    assert r.returncode == 2 and "--max 'ten'" in r.stderr
    r = subprocess.run(["bash", SCRIPT, str(tree / "framework")], capture_output=True, text=True)
    assert r.returncode != 0 and "expected the root of a Binocle tree" in r.stderr


def test_long_raw_string_with_braces_passes(tree):
    braces = "".join("  }}} { ) ( \" ' /* // \n" for _ in range(150))
    plant(tree, "framework/core/a.cpp",
          f'const char *kTable = R"json(\n{braces})json";\n'
          f'const char *kOther = u8R"x(\n{braces})" still inside )x";\n'
          + function("g", 20))
    rc, out = check(tree)
    assert rc == 0, out
    assert "ok: 1 functions" in out


def test_raw_string_inside_a_function_counts_its_lines(tree):
    plant(tree, "framework/core/a.cpp",
          "int f() {\n    const char *s = R\"(\n" + "}\n" * 99 + ")\";\n    return 0;\n}\n")
    rc, out = check(tree)
    assert rc == 1 and "a.cpp:1: f: 104 lines" in out


def test_long_class_with_short_methods_passes(tree):
    methods = "".join(f"    int m{k}(int x) const {{\n        return x + {k};\n    }}\n" for k in range(60))
    plant(tree, "framework/core/a.hpp", f"#pragma once\nnamespace n {{\nclass Big : public Base {{\npublic:\n"
          f"    Big() : a_(1), b_{{2}} {{}}\n{methods}private:\n    int a_;\n    int b_;\n}};\n}}  // namespace n\n")
    rc, out = check(tree)
    assert rc == 0, out
    assert "ok: 61 functions" in out


def test_long_namespace_scope_table_and_enum_pass(tree):
    rows = "".join(f'    {{"key{k}", {{{k}, \'{{\'}}, [] {{ return {k}; }}}},\n' for k in range(120))
    enum = "".join(f"    E{k},\n" for k in range(120))
    plant(tree, "framework/core/a.cpp",
          f"namespace {{\nconst Row kRows[] = {{\n{rows}}};\nenum class E : int {{\n{enum}}};\n"
          f"struct Point {{ int x; }} kPoints[] = {{\n" + "    {1},\n" * 120 + "};\n}  // namespace\n"
          'extern "C" {\n' + function("cEntry", 10) + "}\n")
    rc, out = check(tree)
    assert rc == 0, out


def test_long_comment_passes_and_is_not_counted(tree):
    comment = "".join(f"// line {k} with a brace {{ and a string \"\n" for k in range(150))
    block = "/*\n" + "}} { int f() {\n" * 150 + "*/\n"
    plant(tree, "framework/core/a.cpp", comment + block + function("f", 100).replace(
        "    return x;", "    /* } */ return x; // {\n    // }"))
    rc, out = check(tree)
    assert rc == 1 and f"a.cpp:{150 + 152 + 1}: f: 101 lines" in out


def test_literals_and_preprocessor_lines_do_not_count_as_braces(tree):
    plant(tree, "framework/core/a.cpp", textwrap.dedent("""
        #define OPEN {
        #define CLOSE \\
            }
        int f(int x) {
            char c = '{';
            const char *s = "}}} \\" {";
            int n = 1'000'000;
        #if defined(A)
            if (x) {
        #else
            if (!x) {
        #endif
                x += n;
            }
            return c + s[0] + x;
        }
        """) + function("g", 101))
    rc, out = check(tree)
    assert rc == 1, out
    assert "a.cpp:17: g: 101 lines" in out and "a.cpp:4" not in out


def test_constructors_operators_templates_and_macros_are_functions(tree):
    plant(tree, "plugins/x/a.cpp",
          function("", 101, "Widget::Widget(int a)\n    : a_(a),\n      b_{a}")
          + function("", 101, "bool Widget::operator==(const Widget &o) const noexcept")
          + function("", 101, "template <typename T,\n          typename U>\nauto pick(T t, U u) -> decltype(t + u)")
          + function("", 101, "PYBIND11_MODULE(_binocle, m)")
          + function("", 101, "TEST(Suite, Name)")
          + "struct S {\n" + function("", 101, "    void member() const override") + "};\n")
    rc, out = check(tree)
    assert rc == 1
    for line, name in [(1, "Widget::Widget"), (102, "Widget::operator=="), (203, "pick"),
                       (304, "PYBIND11_MODULE(_binocle, m)"), (405, "TEST(Suite, Name)"), (507, "member")]:
        assert f"plugins/x/a.cpp:{line}: {name}: 101 lines" in out
    assert "6 problem(s)" in out


def test_lambdas(tree):
    inner = "    auto cb = [&](int y) {\n" + body(60, "        ") + "        return y;\n    };\n"
    plant(tree, "sdk/a.cpp",
          "int holder(int x) {\n" + inner + body(40) + "    return cb(x);\n}\n"  # 106 lines: the holder's
          + "Register command{\n    \"name\",\n    [](const Args &args) -> int {\n" + body(98, "        ")
          + "        return 0;\n    }};\n")
    rc, out = check(tree)
    assert rc == 1
    assert "sdk/a.cpp:1: holder: 106 lines" in out
    assert "sdk/a.cpp:109: lambda in 'Register command': 101 lines" in out
    assert "2 problem(s)" in out


def test_every_tree_and_template_file_is_read_and_tests_are_not(tree):
    for rel in ["framework/a.cc", "plugins/p/b.cpp.in", "sdk/include/c.h", "python/d.cpp", "base/e.inl",
                "tests/f.cpp", "framework/g.py", "framework/h.cmake.in"]:
        plant(tree, rel, function("f", 101))
    rc, out = check(tree)
    assert rc == 1
    for rel in ["framework/a.cc", "plugins/p/b.cpp.in", "sdk/include/c.h", "python/d.cpp", "base/e.inl"]:
        assert f"{rel}:1: f: 101 lines" in out
    assert "5 problem(s)" in out


def test_unbalanced_file_is_reported(tree):
    plant(tree, "framework/a.cpp", "int f() {\n    return 0;\n")
    rc, out = check(tree)
    assert rc == 1 and "framework/a.cpp: cannot measure its functions" in out and "never closes" in out
