#!/usr/bin/env python3
"""Lists the C++ functions longer than a limit (issue 36: "no giant functions").

Usage: long_functions.py [--max N] [--fail] FOLDER_OR_FILE...
  Scans every .cc and .h file under the given folders (or the given files) and prints, longest
  first, one line per function definition longer than N lines (default 80):
      path:line name N lines
  then the count ("K functions over N lines"). With --fail the exit status is 1 when K > 0.

A function's length runs from the line of its name to the line of its closing brace, both
included. What counts as a function definition (a heuristic, not a C++ parser):
  - comments, string literals (raw strings too), character literals and preprocessor lines are
    blanked first, so braces inside them do not count;
  - a '{' at namespace, class or extern "C" scope whose declaration has a parameter list, followed
    only by qualifiers (const, noexcept(...), override, final, &, &&, -> trailing type,
    requires ...) or a constructor's initializer list, opens a function body. Class, struct,
    union, enum and namespace bodies, and initializers (`= {...}`, `x{...}`, `f({...})`,
    lambdas assigned at namespace scope) do not;
  - everything between a body's braces (lambdas, local classes, blocks) belongs to that function.
Inline member functions are named Class::method.
"""
import argparse
import os
import re
import sys

SOURCE_SUFFIXES = (".cc", ".h")

# Words before a '(' that do not name the function whose parameter list the '(' opens.
NOT_A_NAME = {
    "alignas", "alignof", "decltype", "noexcept", "sizeof", "static_assert", "requires",
    "__attribute__", "__declspec", "throw", "explicit", "if", "for", "while", "switch", "return",
    "catch", "typeid",
}
# What may stand between a parameter list's ')' and the body's '{'.
QUALIFIERS = {"const", "volatile", "noexcept", "override", "final", "mutable", "constexpr",
              "try", "&", "&&"}
CLASS_KEYS = {"class", "struct", "union"}
MACRO_RE = re.compile(r"[A-Z][A-Z0-9_]+")


def strip_source(text):
    """Returns text with comments, string and character literals and preprocessor lines replaced
    by spaces (newlines kept, so offsets and line numbers are unchanged). A string keeps its
    quotes: "a{b" becomes "   "."""
    out = list(text)
    n = len(text)
    i = 0
    at_line_start = True  # only whitespace so far on this line

    def blank(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            at_line_start = True
            i += 1
            continue
        if c in " \t\r\f\v":
            i += 1
            continue
        if at_line_start and c == "#":
            # Preprocessor directive, with its backslash continuations and comments.
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    j += 2
                    continue
                if text.startswith("/*", j):
                    end = text.find("*/", j + 2)
                    j = n if end < 0 else end + 2
                    continue
                if text.startswith("//", j):
                    while j < n and text[j] != "\n":
                        j += 1
                    break
                j += 1
            blank(i, j)
            i = j
            continue
        at_line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
            continue
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            j = n if end < 0 else end + 2
            blank(i, j)
            i = j
            continue
        if c == '"':
            raw = _raw_string_prefix(text, i)
            if raw is not None:
                j = _raw_string_end(text, i, raw)
            else:
                j = _quoted_end(text, i, '"')
            blank(i + 1, j - 1)
            i = j
            continue
        if c == "'":
            if _is_digit_separator(text, i):
                i += 1
                continue
            j = _quoted_end(text, i, "'")
            blank(i + 1, j - 1)
            i = j
            continue
        i += 1
    return "".join(out)


def _raw_string_prefix(text, i):
    """If the '"' at i opens a raw string (R"delim( with an optional u8/u/U/L prefix), returns
    its delimiter; else None."""
    if i == 0 or text[i - 1] != "R":
        return None
    k = i - 1
    while k > 0 and (text[k - 1].isalnum() or text[k - 1] == "_"):
        k -= 1
    if text[k:i] not in ("R", "u8R", "uR", "UR", "LR"):
        return None
    paren = text.find("(", i + 1)
    if paren < 0 or paren - i - 1 > 16:
        return None
    return text[i + 1:paren]


def _raw_string_end(text, i, delim):
    end = text.find(")" + delim + '"', i + 1)
    return len(text) if end < 0 else end + len(delim) + 2


def _quoted_end(text, i, quote):
    """Index just past the literal opened by the quote at i (stops at an unescaped newline)."""
    j = i + 1
    n = len(text)
    while j < n:
        c = text[j]
        if c == "\\":
            j += 2
            continue
        if c == quote:
            return j + 1
        if c == "\n":
            return j
        j += 1
    return n


def _is_digit_separator(text, i):
    """True for the ' in 1'000'000 or 0xFF'FF: the alphanumeric run before it starts with a
    digit (a character literal's prefix, u8'a' or L'a', starts with a letter)."""
    k = i
    while k > 0 and (text[k - 1].isalnum() or text[k - 1] in "_.'"):
        k -= 1
    return k < i and text[k].isdigit() and i + 1 < len(text) and text[i + 1].isalnum()


TOKEN_RE = re.compile(
    r"\s+"
    r"|(?P<op>\boperator\b\s*(?:\(\s*\)|\[\s*\]|(?:new|delete)\b(?:\s*\[\s*\])?|\"\s*\"\s*\w+"
    r"|[+\-*/%^&|~!=<>,]+|[A-Za-z_][\w:<>\s*&]*?(?=\s*\()))"
    r"|(?P<id>[A-Za-z_]\w*)"
    r"|(?P<num>\d[\w.']*)"
    r"|(?P<punct>::|->|&&|\.\.\.|[^\s\w])")


def tokenize(head):
    """The tokens of a declaration's text (already stripped): identifiers, operator names
    (operator==, operator() ...) as one token, numbers, '::', '->', '&&', '...' and single
    punctuation characters."""
    tokens = []
    for m in TOKEN_RE.finditer(head):
        op = m.group("op")
        if op:
            if re.match(r"operator\s+[A-Za-z_]", op):
                tokens.append(("id", " ".join(op.split())))  # operator bool
            else:
                tokens.append(("id", re.sub(r"\s+", "", op)))  # operator==
        elif m.group("id"):
            tokens.append(("id", m.group("id")))
        elif m.group("num"):
            tokens.append(("num", m.group("num")))
        elif m.group("punct"):
            tokens.append(("p", m.group("punct")))
    return tokens


def top_level(tokens):
    """Yields (index, token, depth) with depth = nesting in (), [], {} and template <> (a '<'
    opens only after an identifier, '>' and '>>' close only an open '<')."""
    stack = []
    for idx, tok in enumerate(tokens):
        kind, v = tok
        depth = len(stack)
        if kind == "p":
            if v in "([{":
                stack.append(v)
            elif v == "<" and idx > 0 and tokens[idx - 1][0] == "id":
                stack.append(v)
            elif v in ")]}":
                while stack and stack[-1] == "<":
                    stack.pop()
                if stack:
                    stack.pop()
                depth = len(stack)
            elif v == ">" and stack and stack[-1] == "<":
                stack.pop()
                depth = len(stack)
        yield idx, tok, depth


class Head:
    """What the text before a '{' at namespace or class scope declares."""

    def __init__(self, kind, name=None, name_offset=None):
        # "function", "class", "namespace", "init" (a brace initializer, which ends the
        # declaration's text once closed) or "nested" (a brace inside the declaration, which
        # goes on after it: a_{1} in a constructor's initializer list, f({1, 2}))
        self.kind = kind
        self.name = name
        self.name_offset = name_offset  # token index of the name's first token


def classify_head(text):
    """Classifies the '{' that follows text (a declaration at namespace or class scope, from the
    end of the one before it)."""
    tokens = tokenize(text)
    if not tokens:
        return Head("init")
    if _final_depth(tokens) > 0:
        return Head("nested")  # inside an argument list: f({...}), a_(Options{})
    levels = list(top_level(tokens))
    words = [v for _, (kind, v), d in levels if d == 0 and kind == "id"]
    if "namespace" in words or (words and words[0] == "extern" and len(tokens) <= 3):
        return Head("namespace")
    if "enum" in words:
        return Head("init")
    # The parameter list: the first top-level '(' after a name that is not a keyword.
    call = None
    for idx, (kind, v), depth in levels:
        if depth == 0 and kind == "p" and v == "(" and idx > 0:
            pk, pv = tokens[idx - 1]
            if pk == "id" and MACRO_RE.fullmatch(pv) and idx > 1 and \
                    tokens[idx - 2][1] in CLASS_KEYS:
                continue  # class CAPABILITY("mutex") Mutex
            if pk == "id" and pv not in NOT_A_NAME:
                call = idx
                break
            if pk == "p" and pv == ">":
                call = idx  # Foo<T>::Foo(...) or a call to a template: decided below
                break
    if call is None:
        for i, (kind, v), depth in levels:
            if depth == 0 and kind == "id" and v in CLASS_KEYS:
                return Head("class", _class_name(tokens, i))
        return Head("init")
    # '=' at top level before the parameter list: an initializer (a lambda, a call).
    for idx, (kind, v), depth in levels[:call]:
        if depth == 0 and kind == "p" and v == "=":
            return Head("init")
    close = _matching(tokens, call)
    if close is None:
        return Head("init")
    rest = tokens[close + 1:]
    tail = _body_tail(rest)
    if tail != "body":
        return Head(tail)
    name, first = _name_before(tokens, call)
    if name is None:
        return Head("init")
    if MACRO_RE.fullmatch(name):  # TEST(Suite, Case), TEST_F(...)
        name += "(" + "".join(v if v != "," else ", " for _, v in tokens[call + 1:close]) + ")"
    return Head("function", name, first)


def _final_depth(tokens):
    depth = 0
    for _, v in tokens:
        if v in ("(", "["):
            depth += 1
        elif v in (")", "]"):
            depth = max(0, depth - 1)
    return depth


def _matching(tokens, open_idx):
    depth = 0
    for i in range(open_idx, len(tokens)):
        v = tokens[i][1]
        if v in ("(", "[", "{"):
            depth += 1
        elif v in (")", "]", "}"):
            depth -= 1
            if depth == 0:
                return i
    return None


def _body_tail(rest):
    """What the tokens between a parameter list's ')' and a '{' make of the '{': "body" after
    qualifiers, a trailing return type, a requires clause, or a constructor's initializer list
    whose last initializer is complete (ends in ')' or '}'); "nested" for a brace
    initializer inside that list (a_{1}); "init" otherwise. Upper-case macros, with or without
    arguments, may stand among the qualifiers: void Lock() ACQUIRE() {."""
    i = 0
    while i < len(rest):
        kind, v = rest[i]
        if v in ("->", "requires"):
            return "body"
        if v == ":":
            return "body" if rest[-1][1] in (")", "}") else "nested"
        if v == "[" and i + 1 < len(rest) and rest[i + 1][1] == "[":  # [[attribute]]
            end = _matching(rest, i)
            if end is None:
                return "init"
            i = end + 1
            continue
        if v in QUALIFIERS or (kind == "id" and MACRO_RE.fullmatch(v)):
            if i + 1 < len(rest) and rest[i + 1][1] == "(":
                end = _matching(rest, i + 1)
                if end is None:
                    return "init"
                i = end + 1
                continue
            i += 1
            continue
        return "init"
    return "body"


def _name_before(tokens, call):
    """The (qualified) name ending just before tokens[call]: Foo::Bar, Foo::~Foo, Foo<T>::Baz,
    operator==. Returns (name, index of its first token) or (None, None)."""
    i = call - 1
    parts = []
    while i >= 0:
        kind, v = tokens[i]
        if v == ">":  # template arguments: Foo<T>::Bar, f<3>(...)
            j = _matching_angle(tokens, i)
            if j is None:
                return None, None
            parts.append("".join(t[1] for t in tokens[j:i + 1]))
            i = j - 1
            continue
        if kind != "id":
            break
        parts.append(v)
        i -= 1
        if i >= 0 and tokens[i][1] == "~":
            parts.append("~")
            i -= 1
        if i >= 0 and tokens[i][1] == "::":
            parts.append("::")
            i -= 1
            continue
        break
    if not parts or parts[-1] == "::" or parts[-1].startswith("<"):
        return None, None
    return "".join(reversed(parts)), i + 1


def _matching_angle(tokens, close_idx):
    depth = 0
    for j in range(close_idx, -1, -1):
        v = tokens[j][1]
        if v == ">":
            depth += 1
        elif v == "<":
            depth -= 1
            if depth == 0:
                return j
    return None


def _class_name(tokens, key_idx):
    i = key_idx + 1
    while i < len(tokens):
        kind, v = tokens[i]
        if v == "[":
            end = _matching(tokens, i)
            i = (end if end is not None else i) + 1
            continue
        if kind == "id" and (v in ("alignas", "__attribute__", "__declspec") or
                             MACRO_RE.fullmatch(v)):
            if i + 1 < len(tokens) and tokens[i + 1][1] == "(":
                end = _matching(tokens, i + 1)
                i = (end if end is not None else i) + 1
                continue
        if kind == "id" and MACRO_RE.fullmatch(v) and i + 1 < len(tokens) and \
                tokens[i + 1][0] == "id":
            i += 1  # class SCOPED_CAPABILITY MutexLock
            continue
        if kind == "id" and v != "final":
            name = v
            while i + 2 < len(tokens) and tokens[i + 1][1] == "::" and tokens[i + 2][0] == "id":
                name += "::" + tokens[i + 2][1]
                i += 2
            return name
        break
    return None


ACCESS_RE = re.compile(r"\b(?:public|private|protected)\s*:(?!:)")


class Scanner:
    def __init__(self, text):
        self.raw = text
        self.text = strip_source(text)
        self.line_starts = [0] + [m.end() for m in re.finditer("\n", text)]
        self.functions = []  # (name, first line, last line)

    def line_of(self, offset):
        lo, hi = 0, len(self.line_starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self.line_starts[mid] <= offset:
                lo = mid
            else:
                hi = mid - 1
        return lo + 1

    def scan(self):
        self._scope(0, None)
        return self.functions

    def _skip_block(self, pos):
        """pos is just past a '{'; returns the index just past its matching '}'."""
        depth = 1
        text = self.text
        n = len(text)
        while pos < n:
            c = text[pos]
            if c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
                if depth == 0:
                    return pos + 1
            pos += 1
        return n

    def _scope(self, pos, class_name):
        """Scans a namespace (class_name None) or class body from pos to its closing '}';
        returns the index just past it."""
        text = self.text
        n = len(text)
        head_start = pos
        while pos < n:
            c = text[pos]
            if c == ";":
                head_start = pos + 1
            elif c == "}":
                return pos + 1
            elif c == "{":
                head_text = text[head_start:pos]
                m = None
                for m in ACCESS_RE.finditer(head_text):
                    pass
                if m is not None:
                    head_start += m.end()
                    head_text = head_text[m.end():]
                head = classify_head(head_text)
                if head.kind == "function":
                    end = self._skip_block(pos + 1)
                    name_at = head_start + _offset_of_token(head_text, head.name_offset)
                    name = head.name
                    if class_name and "::" not in name.split("(")[0]:
                        name = class_name + "::" + name
                    self.functions.append(
                        (name, self.line_of(name_at), self.line_of(end - 1)))
                    pos = end
                    head_start = pos
                    continue
                if head.kind in ("namespace", "class"):
                    inner = head.name if head.kind == "class" else None
                    if inner and class_name:
                        inner = class_name + "::" + inner
                    pos = self._scope(pos + 1, inner)
                    head_start = pos
                    continue
                pos = self._skip_block(pos + 1)
                if head.kind != "nested":
                    head_start = pos
                continue
            pos += 1
        return n


def _offset_of_token(head_text, token_index):
    """Character offset in head_text of the token_index-th token."""
    count = 0
    for m in TOKEN_RE.finditer(head_text):
        if m.group("op") or m.group("id") or m.group("num") or m.group("punct"):
            if count == token_index:
                return m.start()
            count += 1
    return 0


def long_functions(text, limit):
    """(name, first line, lines) for each function in text longer than limit lines."""
    found = []
    for name, first, last in Scanner(text).scan():
        lines = last - first + 1
        if lines > limit:
            found.append((name, first, lines))
    return found


def source_files(paths):
    for path in paths:
        if os.path.isfile(path):
            yield path
            continue
        for root, dirs, files in os.walk(path):
            dirs.sort()
            for f in sorted(files):
                if f.endswith(SOURCE_SUFFIXES):
                    yield os.path.join(root, f)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("paths", nargs="+", metavar="FOLDER_OR_FILE")
    ap.add_argument("--max", type=int, default=80, help="longest allowed function (lines)")
    ap.add_argument("--fail", action="store_true", help="exit 1 when any function is longer")
    args = ap.parse_args(argv)
    for p in args.paths:
        if not os.path.exists(p):
            ap.error(f"{p}: no such file or folder; give folders or .cc/.h files to scan")
    found = []
    for path in source_files(args.paths):
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        for name, line, lines in long_functions(text, args.max):
            found.append((lines, path, line, name))
    found.sort(key=lambda r: (-r[0], r[1], r[2]))
    for lines, path, line, name in found:
        print(f"{path}:{line} {name} {lines} lines")
    print(f"{len(found)} functions over {args.max} lines")
    return 1 if args.fail and found else 0


if __name__ == "__main__":
    sys.exit(main())
