#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# No function over 100 lines (docs/DEVELOPING.md): fails (exit 1), naming file:line, the
# function and its length, for every function definition in the C and C++ files of
# framework/, plugins/, sdk/, python/ and base/ (those present) longer than the limit,
# counted from the first line of its signature (template and attribute lines included) to
# its closing brace.
#   - Files: .h .hpp .c .cpp .cc .inl, and the .in templates of those (x.cpp.in).
#   - A function: a free or member function defined in or out of its class, a constructor
#     (its member-initialiser list is part of it), an operator, a template, and the body of
#     a function-like macro (`TEST(Suite, Name) { ... }`, `PYBIND11_MODULE(m, m) { ... }`).
#     A lambda is part of the function holding it; a lambda outside any function (in a
#     namespace-scope initialiser such as `Register x{"n", [](...) { ... }}`, or a default
#     member initialiser) is a function of its own, counted from its `[`.
#   - Not functions: namespace, class, enum and extern "C" blocks and initialiser braces
#     (a long table or a long class of short methods passes).
#   - A signature starts at the first token after the previous `;`, `{`, `}` or access
#     label (public:) of its scope: a macro call written there without a `;` counts
#     with the function that follows it.
#   - Comments, string and character literals (raw strings R"x(...)x" too) and
#     preprocessor lines are read as such, never as code. Where the branches of an
#     #if/#elif/#else do not each balance their braces and parentheses (two openings of one
#     function, say), only the first branch is read, as the compiler would see one.
# A file whose braces still do not balance is reported (exit 1): the check cannot measure it.
# Usage: scripts/check-function-length.sh [SOURCE_DIR] [--max N]
#   SOURCE_DIR: the tree holding this script by default; N: 100 by default.
# Run by CTest as `check_function_length` (tests/layers/CMakeLists.txt).
set -euo pipefail
root=""
max=100
while [ $# -gt 0 ]; do
  case "$1" in
    --max)
      [ $# -ge 2 ] || { echo "check-function-length: --max needs a number of lines (e.g. --max 100)" >&2; exit 2; }
      max="$2"; shift 2 ;;
    --max=*) max="${1#--max=}"; shift ;;
    -*) echo "check-function-length: unknown option '$1'; expected [SOURCE_DIR] [--max N]" >&2; exit 2 ;;
    *)
      [ -z "$root" ] || { echo "check-function-length: one SOURCE_DIR only, got '$root' and '$1'" >&2; exit 2; }
      root="$1"; shift ;;
  esac
done
case "$max" in
  ''|*[!0-9]*|0) echo "check-function-length: --max '$max': expected a whole number of lines above 0" >&2; exit 2 ;;
esac
root="${root:-$(cd "$(dirname "$0")/.." && pwd)}"
exec python3 - "$root" "$max" <<'PY'
import bisect
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1])
MAX = int(sys.argv[2])
TOPS = ("framework", "plugins", "sdk", "python", "base")
SUFFIXES = (".h", ".hpp", ".c", ".cpp", ".cc", ".inl")

present = [t for t in TOPS if os.path.isdir(os.path.join(ROOT, t))]
if not present:
    sys.exit(f"check-function-length: {ROOT}: none of {', '.join(t + '/' for t in TOPS)}: "
             "expected the root of a Binocle tree")

# One token a match. Comments, literals and preprocessor lines come first, so that what
# they hold is never read as code; the preprocessor line is matched from the start of its
# line (leading blanks included), its continuation lines and comments with it.
TOKEN = re.compile(r"""
    (?P<comment>//[^\n]*|/\*.*?\*/)
  | (?P<pp>^[ \t]*\#(?:/\*.*?\*/|\\\n|[^\n])*)
  | (?P<raw>(?:u8|u|U|L)?R"(?P<delim>[^()\\\s"]{0,16})\(.*?\)(?P=delim)")
  | (?P<lit>(?:u8|u|U|L)?"(?:\\.|[^"\\\n])*"|(?:u8|u|U|L)?'(?:\\.|[^'\\\n])*')
  | (?P<num>\.?[0-9](?:[eEpP][+-]|'[0-9A-Za-z_]|[0-9A-Za-z_.])*)
  | (?P<ident>[A-Za-z_$][A-Za-z_0-9$]*)
  | (?P<punct>::|->\*?|\.\.\.|<<=|>>=|[-+*/%&|^!=<>]=|&&|\|\||\+\+|--|<<|>>|\S)
""", re.X | re.S | re.M)

# What may stand between the parameters and the body of a function or lambda.
QUALIFIERS = {"const", "volatile", "noexcept", "override", "final", "mutable", "constexpr",
              "consteval", "throw", "try", "__attribute__", "alignas", "&", "&&"}
CLASS_KEYS = {"class", "struct", "union"}
ACCESS = {"public", "private", "protected"}


class Tok:
    __slots__ = ("kind", "text", "line")

    def __init__(self, kind, text, line):
        self.kind, self.text, self.line = kind, text, line


def tokens_of(text):
    newlines = [m.start() for m in NEWLINE.finditer(text)]
    out = []
    for m in TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "delim":
            kind = "raw"
        if kind == "comment":
            continue
        if kind == "raw":
            kind = "lit"
        line = bisect.bisect_right(newlines, m.start()) + 1
        if kind == "pp":
            line = bisect.bisect_right(newlines, m.start() + len(m.group()) - len(m.group().lstrip())) + 1
        out.append(Tok(kind, m.group() if kind != "pp" else m.group().strip(), line))
    return out


NEWLINE = re.compile(r"\n")
PP_WORD = re.compile(r"#\s*(\w+)")


def balance(toks):
    braces = parens = 0
    for t in toks:
        if t.kind == "punct":
            braces += (t.text == "{") - (t.text == "}")
            parens += (t.text in "([") - (t.text in ")]")
    return braces, parens


def keep_balanced_branches(toks):
    """The tokens the check reads: preprocessor lines dropped; of an #if group whose
    branches do not each balance, the first branch only (innermost groups first)."""

    def group(i):
        # toks[i] opens an #if group: returns (kept tokens, index after its #endif).
        branches, current, i = [], [], i + 1
        while i < len(toks):
            t = toks[i]
            word = PP_WORD.match(t.text).group(1) if t.kind == "pp" and PP_WORD.match(t.text) else None
            if word in ("if", "ifdef", "ifndef"):
                kept, i = group(i)
                current.extend(kept)
                continue
            if word in ("elif", "else", "elifdef", "elifndef"):
                branches.append(current)
                current = []
            elif word == "endif":
                branches.append(current)
                if len(branches) > 1 and any(balance(b) != (0, 0) for b in branches):
                    return branches[0], i + 1
                return [t for b in branches for t in b], i + 1
            elif t.kind != "pp":
                current.append(t)
            i += 1
        branches.append(current)  # no #endif: read as it stands
        return [t for b in branches for t in b], i

    out, i = [], 0
    while i < len(toks):
        t = toks[i]
        m = PP_WORD.match(t.text) if t.kind == "pp" else None
        if m and m.group(1) in ("if", "ifdef", "ifndef"):
            kept, i = group(i)
            out.extend(kept)
            continue
        if t.kind != "pp":
            out.append(t)
        i += 1
    return out


class Frame:
    """An open bracket outside any function body: a scope (file, namespace, class,
    extern "C"), an initialiser (enum bodies too) or a ( / [ group. It reads the
    declaration being written inside it (its head) to tell what a `{` opens."""
    __slots__ = ("kind", "start", "state", "params", "lambda_at", "opened_at", "saved", "meminit")

    def __init__(self, kind, opened_at=None, saved=None, meminit=False):
        self.kind = kind            # 'scope', 'init', '(' or '['
        self.opened_at = opened_at  # token index of the opening bracket
        self.saved = saved          # the parent's (state, params, lambda_at) when a group opened
        self.meminit = meminit      # an initialiser of a constructor's member-initialiser list
        self.reset()

    def reset(self):
        self.start = None       # token index where the head begins
        self.state = "none"     # 'none', 'params', 'trailing' (-> type), 'ctorinit', 'lambda'
        self.params = None      # token index of the '(' of the parameters
        self.lambda_at = None   # token index of a lambda's '['


def head_kind(toks, start, end):
    """What a `{` that follows no parameters opens: 'scope' or 'init'."""
    words = [t.text for t in toks[start:end]]
    if words and words[0] == "template":  # skip the template's parameter list
        depth, j = 0, 1
        while j < len(words):
            depth += (words[j] == "<") - (words[j] == ">") - 2 * (words[j] == ">>")
            j += 1
            if depth <= 0:
                break
        words = words[j:]
    if "=" in words or "enum" in words:
        return "init"
    if "namespace" in words or words[:1] == ["extern"] or CLASS_KEYS & set(words):
        return "scope"
    return "init"


def function_name(toks, params, lambda_at, frames):
    if lambda_at is not None:
        scope = next((f for f in reversed(frames) if f.kind == "scope" and f.start is not None), None)
        if scope is not None:
            words = []
            for t in toks[scope.start:lambda_at]:
                if t.text in ("=", "{", "("):
                    break
                words.append(t.text)
            if words:
                return "lambda in '" + " ".join(words[-4:]).replace(" :: ", "::") + "'"
        return "lambda"
    j, parts = params - 1, []
    while j >= 0 and len(parts) < 16:
        t = toks[j]
        if t.kind == "ident" or t.text in ("::", "~"):
            parts.append(t.text)
        elif j > 0 and toks[j - 1].text == "operator":
            parts.append(t.text)
        elif t.text == ")" and j > 1 and toks[j - 1].text == "(" and toks[j - 2].text == "operator":
            parts.append("()")
            j -= 1
        elif t.text == "]" and j > 1 and toks[j - 1].text == "[" and toks[j - 2].text == "operator":
            parts.append("[]")
            j -= 1
        elif t.text == ">":  # template arguments of a qualified name: Foo<T>::bar
            depth, k = 0, j
            while k >= 0:
                depth += (toks[k].text == ">") - (toks[k].text == "<")
                if depth == 0:
                    break
                k -= 1
            if k <= 0 or toks[k - 1].kind != "ident":
                break
            parts.append(" ".join(x.text for x in toks[k:j + 1]).replace(" ", ""))
            j = k
        else:
            break
        if t.kind == "ident" and (j == 0 or toks[j - 1].text not in ("::", "~", "operator")):
            break
        j -= 1
    name = "".join(reversed(parts)) or "?"
    if re.fullmatch(r"[A-Z][A-Z0-9_]*", name):  # a macro: TEST(Suite, Name)
        depth, k = 0, params
        while k < len(toks):
            depth += (toks[k].text in "([") - (toks[k].text in ")]")
            if depth == 0:
                break
            k += 1
        arguments = " ".join(t.text for t in toks[params + 1:k]).replace(" ,", ",")
        name += f"({arguments[:60]})"
    return name


class Unbalanced(Exception):
    pass


def functions_of(toks):
    """(first line, last line, name) of each function definition, outermost only."""
    found = []
    frames = [Frame("scope")]
    i, n = 0, len(toks)
    while i < n:
        t, f = toks[i], frames[-1]
        x = t.text if t.kind == "punct" else None
        if f.start is None and x != ";":
            f.start = i
        if x == "{":
            prev = toks[i - 1].text if i > 0 else ""
            body = f.state in ("params", "trailing", "lambda") or (
                f.state == "ctorinit" and prev in (")", "}", "..."))
            if body:
                # Skip the body: a lambda, a local class, anything in it is the function's.
                first = toks[f.lambda_at].line if f.lambda_at is not None else toks[f.start].line
                name = function_name(toks, f.params, f.lambda_at, frames) if (
                    f.params is not None or f.lambda_at is not None) else "?"
                depth, j = 0, i
                while j < n:
                    if toks[j].kind == "punct":
                        depth += (toks[j].text == "{") - (toks[j].text == "}")
                        if depth == 0:
                            break
                    j += 1
                if j == n:
                    raise Unbalanced(f"the body of '{name}' opened at line {t.line} never closes")
                found.append((first, toks[j].line, name))
                if f.lambda_at is not None:
                    f.state, f.params, f.lambda_at = "none", None, None
                else:
                    f.reset()
                i = j + 1
                continue
            if f.state == "ctorinit":
                frames.append(Frame("init", i, meminit=True))
            elif f.kind == "scope" and head_kind(toks, f.start, i) == "scope":
                frames.append(Frame("scope", i))
            else:
                frames.append(Frame("init", i))
        elif x == "}":
            if f.kind in ("(", "["):
                raise Unbalanced(f"'}}' at line {t.line} closes a '{f.kind}' opened at line {toks[f.opened_at].line}")
            if len(frames) == 1:
                raise Unbalanced(f"'}}' at line {t.line} closes nothing")
            frames.pop()
            parent = frames[-1]
            if f.kind == "scope":
                parent.reset()
            elif not f.meminit:
                parent.state, parent.params, parent.lambda_at = "none", None, None
        elif x in ("(", "["):
            prev = toks[i - 1] if i > 0 else None
            lambda_intro = x == "[" and (prev is None or (
                prev.kind == "punct" and prev.text not in (")", "]", ">")) or prev.text == "return")
            frames.append(Frame(x, i, (f.state, f.params, f.lambda_at, lambda_intro)))
        elif x in (")", "]"):
            if f.kind != ("(" if x == ")" else "["):
                raise Unbalanced(f"'{x}' at line {t.line} does not close what is open"
                                 + (f" ('{f.kind}' at line {toks[f.opened_at].line})" if f.opened_at is not None else ""))
            frames.pop()
            parent = frames[-1]
            state, params, lambda_at, lambda_intro = f.saved
            if state in ("trailing", "ctorinit"):
                pass
            elif x == "]":
                if lambda_intro:
                    parent.state, parent.lambda_at, parent.params = "lambda", f.opened_at, None
                else:
                    parent.state = "none"
            else:
                before = toks[f.opened_at - 1].text if f.opened_at > 0 else ""
                if state == "params" and before in QUALIFIERS:  # noexcept(...), __attribute__((...))
                    pass
                else:
                    parent.state = "params"
                    parent.params = f.opened_at
                    parent.lambda_at = lambda_at if state == "lambda" else None
        elif x == ";":
            f.reset()
        elif x == ",":
            if f.kind != "scope":
                f.reset()
            elif f.state != "ctorinit":
                f.state = "none"
        elif x == ":" and i > 0 and toks[i - 1].text in ACCESS and f.kind == "scope":
            f.reset()
        elif f.state == "params":
            if x == "->":
                f.state = "trailing"
            elif x == ":":
                f.state = "ctorinit"
            elif t.text in QUALIFIERS or (t.kind == "ident" and re.fullmatch(r"[A-Z][A-Z0-9_]+", t.text)):
                pass  # const, noexcept, override, a macro standing for one (BINOCLE_NOEXCEPT)
            else:
                f.state, f.params, f.lambda_at = "none", None, None
        elif f.state == "lambda":
            if x == "->" or t.text in QUALIFIERS:
                f.state = "params" if x != "->" else "trailing"
                f.params = None
            else:
                f.state, f.lambda_at = "none", None
        i += 1
    if len(frames) > 1:
        g = frames[-1]
        raise Unbalanced(f"'{toks[g.opened_at].text}' opened at line {toks[g.opened_at].line} never closes")
    return found


def files():
    for top in present:
        for base, dirs, names in os.walk(os.path.join(ROOT, top)):
            dirs.sort()
            for name in sorted(names):
                stem = name[:-3] if name.endswith(".in") else name
                if stem.endswith(SUFFIXES):
                    yield os.path.join(base, name)


problems, checked, measured = [], 0, 0
for path in files():
    rel = os.path.relpath(path, ROOT)
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    checked += 1
    try:
        found = functions_of(keep_balanced_branches(tokens_of(text)))
    except Unbalanced as e:
        problems.append(f"{rel}: cannot measure its functions: {e}")
        continue
    measured += len(found)
    for first, last, name in found:
        length = last - first + 1
        if length > MAX:
            problems.append(f"{rel}:{first}: {name}: {length} lines (lines {first}-{last}), over {MAX}")

if problems:
    for p in problems:
        print(f"check-function-length: {p}")
    print(f"check-function-length: {len(problems)} problem(s) in {ROOT}: split each function into named "
          f"steps of at most {MAX} lines (docs/DEVELOPING.md)")
    sys.exit(1)
print(f"check-function-length: ok: {measured} functions in {checked} files of "
      f"{', '.join(t + '/' for t in present)}, none over {MAX} lines")
PY
