#!/usr/bin/python3
"""Lists the C++ functions and files over the size limits of the code base.

Usage: scripts/long-functions.py [--max N] [--max-file N] [PATH ...]

Without PATH: every C++ source tracked by git (.h .hpp .cpp .cc .cu .cuh .H .C) outside tests/
and outside third-party or generated code. A PATH (file or directory) restricts the scan to it;
tests/ is then not excluded. Prints one line per finding,
  file:line: function NAME: N lines (limit M)
  file:1: file: N lines (limit M)
and exits 1 when there is one, 0 when there is none.

A function is a free function, a member function (defined in or out of its class) or a lambda
at namespace or class scope; a lambda inside a function is part of that function. Its length
runs from the first line of its declaration (template header included) to its closing brace.
Brace matching heuristic: comments, string, character and raw string literals and preprocessor
lines are blanked first; namespace, extern "C", class, struct, union and enum bodies,
initialisers and constructor initialiser lists are told apart from function bodies by the
tokens before the brace. Standard library only.
"""
import argparse
import os
import re
import subprocess
import sys

EXTENSIONS = (".h", ".hpp", ".hxx", ".cpp", ".cc", ".cxx", ".cu", ".cuh", ".H", ".C")
# Path components that mark code that is not ours to size.
EXCLUDED_PARTS = {"tests", "third_party", "third-party", "thirdparty", "external", "vendor", "_deps"}
GENERATED = re.compile(r"\.pb\.(h|cc)$|_generated\.")

CONTROL = {"if", "else", "for", "while", "do", "switch", "try", "catch", "return"}
QUALIFIERS = {"const", "volatile", "noexcept", "override", "final", "&", "&&", "mutable",
              "constexpr", "throw", "requires", "__device__", "__host__", "try"}
ACCESS = {"public", "private", "protected", "signals", "slots"}



def blank_block_comment(text, i, out):
    """Appends the /* ... */ comment at i as blanks (newlines kept); returns the index past it."""
    end = text.find("*/", i + 2)
    end = len(text) if end < 0 else end + 2
    out.append(re.sub(r"[^\n]", " ", text[i:end]))
    return end

def blank(text):
    """Returns text with comments, literals and preprocessor lines replaced by spaces (string
    and character literals by a placeholder), newlines kept."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if c == "\n":
            out.append(c)
            i += 1
            line_start = True
            continue
        if line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if line_start and c == "#":
            # Preprocessor directive, with its continuation lines and comments.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                if text.startswith("/*", i):
                    i = blank_block_comment(text, i, out)
                    continue
                out.append(" ")
                i += 1
            continue
        line_start = False
        if text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            out.append(" " * (end - i))
            i = end
            continue
        if text.startswith("/*", i):
            i = blank_block_comment(text, i, out)
            continue
        if c == '"':
            prefix = re.search(r"(?:^|[^A-Za-z0-9_])((?:u8|u|U|L)?R)$", text[max(0, i - 3):i])
            if prefix:
                m = re.match(r'"([^()\\\s]{0,16})\(', text[i:])
                if m:
                    close = ")" + m.group(1) + '"'
                    end = text.find(close, i + len(m.group(0)))
                    end = n if end < 0 else end + len(close)
                    body = text[i:end]
                    out.append('"S"' + re.sub(r"[^\n]", " ", body[3:]))
                    i = end
                    continue
            j = i + 1
            while j < n and text[j] != '"' and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append('"S"' + " " * (j - i - 3) if j - i >= 3 else '"S"'[: j - i])
            i = j
            continue
        if c == "'":
            # A digit separator (1'000) or a character literal ('x', u8'x').
            k = i
            while k > 0 and (text[k - 1].isalnum() or text[k - 1] in "_."):
                k -= 1
            if k < i and text[k].isdigit():
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != "'" and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append("'c'" + " " * (j - i - 3) if j - i >= 3 else " " * (j - i))
            i = j
            continue
        out.append(c)
        i += 1
    return "".join(out)


TOKEN = re.compile(r"""
    (?P<id>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<num>\.?[0-9][A-Za-z0-9_.]*)
  | (?P<str>"S"|'c')
  | (?P<op>::|->|&&|\.\.\.|\[\[|\]\]|[{}()\[\]<>;:,=&*~!?+\-/%^|.])
""", re.VERBOSE)


def tokenize(text):
    tokens = []
    line = 1
    pos = 0
    for m in TOKEN.finditer(text):
        line += text.count("\n", pos, m.start())
        pos = m.start()
        tokens.append((m.group(0), line))
    return tokens


def match_braces(tokens):
    """Maps the index of each '{' to the index of its '}' (-1 when unbalanced)."""
    match, stack = {}, []
    for i, (t, _) in enumerate(tokens):
        if t == "{":
            stack.append(i)
        elif t == "}" and stack:
            match[stack.pop()] = i
    for i in stack:
        match[i] = -1
    return match


def depth0(head, pred):
    """Indices of head tokens at parenthesis/bracket depth 0 for which pred(token) holds."""
    depth, found = 0, []
    for i, t in enumerate(head):
        if t in "([":
            depth += 1
        elif t in ")]":
            depth -= 1
        elif depth == 0 and pred(t, i):
            found.append(i)
    return found


def strip_template(head):
    """Drops leading `template <...>` headers and attributes from a declaration's tokens."""
    i = 0
    while i < len(head):
        if head[i] == "template" and i + 1 < len(head) and head[i + 1] == "<":
            depth, j = 0, i + 1
            paren = 0
            while j < len(head):
                t = head[j]
                if t in "([":
                    paren += 1
                elif t in ")]":
                    paren -= 1
                elif paren == 0 and t == "<":
                    depth += 1
                elif paren == 0 and t == ">":
                    depth -= 1
                    if depth == 0:
                        break
                j += 1
            i = j + 1
        elif head[i] == "[[":
            while i < len(head) and head[i] != "]]":
                i += 1
            i += 1
        elif head[i] in ("alignas", "__declspec", "__attribute__") and i + 1 < len(head) \
                and head[i + 1] == "(":
            depth, j = 0, i + 1
            while j < len(head):
                depth += {"(": 1, ")": -1}.get(head[j], 0)
                if depth == 0:
                    break
                j += 1
            i = j + 1
        else:
            break
    return head[i:]


def not_operator_name(head):
    """Head tokens with the tokens of an `operator...` name replaced by a placeholder."""
    out, i = [], 0
    while i < len(head):
        if head[i] == "operator":
            j = i + 1
            if j < len(head) and head[j] == "(":
                j += 2  # operator()
            else:
                while j < len(head) and head[j] != "(":
                    j += 1
            out.append("operator" + "".join(head[i + 1:j]))
            i = j
        else:
            out.append(head[i])
            i += 1
    return out


def params_close(head):
    """Index of the ')' that closes a function's parameter list in head, or None."""
    h = head
    arrow = depth0(h, lambda t, i: t == "->")
    end = arrow[0] if arrow else len(h)
    # Skip qualifiers (const, noexcept(...), override, requires ...) back to the ')'.
    j = end - 1
    while j >= 0:
        t = h[j]
        if t == ")":
            # Is this ')' a noexcept(...)/throw(...) argument?
            depth, k = 0, j
            while k >= 0:
                depth += {")": 1, "(": -1}.get(h[k], 0)
                if depth == 0:
                    break
                k -= 1
            if k > 0 and h[k - 1] in ("noexcept", "throw", "__attribute__"):
                j = k - 2
                continue
            return j
        if t in QUALIFIERS or t == "]]":
            j -= 1
            continue
        if t == "[[":
            j -= 1
            continue
        return None
    return None


def function_name(head, close):
    """The name of the function whose parameter list closes at head[close]."""
    depth, k = 0, close
    while k >= 0:
        depth += {")": 1, "(": -1}.get(head[k], 0)
        if depth == 0:
            break
        k -= 1
    k -= 1

    def skip_args(k):
        """Index before the template argument list that ends at head[k] ('>')."""
        depth = 0
        while k >= 0:
            depth += {">": 1, "<": -1}.get(head[k], 0)
            if depth == 0:
                return k - 1
            k -= 1
        return k

    parts = []
    while k >= 0:
        if head[k] == ">":
            k = skip_args(k)  # an explicit specialisation f<T>( or a class template's X<T>::
        if k < 0 or not re.match(r"[A-Za-z_~]", head[k]):
            break
        parts.insert(0, head[k])
        k -= 1
        if k >= 0 and head[k] == "~":
            parts.insert(0, "~")
            k -= 1
        if k >= 0 and head[k] == "::":
            parts.insert(0, "::")
            k -= 1
            continue
        break
    return "".join(parts) or "?"


def analyse(path, text):
    """Yields (line, name, length) for every function in text."""
    tokens = tokenize(blank(text))
    match = match_braces(tokens)
    words = [t for t, _ in tokens]

    def scan(begin, end, scope):
        """Walks tokens[begin:end] at namespace or class scope `scope` (a list of names)."""
        head = []  # indices of the tokens of the declaration under way
        paren = 0  # parenthesis depth within head
        i = begin
        while i < end:
            t = words[i]
            if t in "([":
                paren += 1
            elif t in ")]":
                paren = max(0, paren - 1)
            if paren > 0 and t == "{":
                # A brace initialiser in parentheses (a default argument `= {}`).
                close = match.get(i, -1)
                head += [i, close if close >= 0 else end - 1]
                i = close + 1 if close >= 0 else end
                continue
            if paren > 0 and t in (";", "}"):
                head.append(i)  # a for statement's `;` in an include fragment's code
                i += 1
                continue
            if t in (";", "}"):
                head = []
                i += 1
                continue
            if t == ":" and head and words[head[-1]] in ACCESS and len(head) == 1:
                head = []
                i += 1
                continue
            if t != "{":
                head.append(i)
                i += 1
                continue
            close = match.get(i, -1)
            if close < 0:
                close = end
            htoks = not_operator_name([words[k] for k in head])
            decl = strip_template(htoks)
            first = decl[0] if decl else ""
            start_line = tokens[head[0]][1] if head else tokens[i][1]
            if first == "namespace" or (first == "inline" and len(decl) > 1
                                        and decl[1] == "namespace"):
                names = [x for x in decl if re.match(r"[A-Za-z_]", x) and x not in
                         ("namespace", "inline")]
                yield from scan(i + 1, close, scope)
                head = []
                i = close + 1
                continue
            if first == "extern" and len(decl) == 2 and decl[1] == '"S"':
                yield from scan(i + 1, close, scope)
                head = []
                i = close + 1
                continue
            if first in CONTROL or not decl:
                # A statement block at file scope: an OpenFOAM include fragment's code.
                head = []
                i = close + 1
                continue
            for kw_pos, kw in enumerate(decl[:3]):
                if kw in ("class", "struct", "union") and "(" not in decl[:kw_pos]:
                    break
            else:
                kw = None
            eqs = depth0(decl, lambda tk, k: tk == "=")
            if kw and not (eqs and "(" in decl[:eqs[0]]):
                # A class body; its name is the identifier before ':' or '{'.
                body = decl[kw_pos + 1:]
                colon = [k for k, x in enumerate(body) if x == ":"]
                body = body[: colon[0]] if colon else body
                ids = [x for x in body if re.match(r"[A-Za-z_]", x) and x not in ("final",)]
                yield from scan(i + 1, close, scope + [ids[-1] if ids else "(anonymous)"])
                head = []
                i = close + 1
                continue
            if first == "enum" or (first == "typedef" and "enum" in decl):
                head = []
                i = close + 1
                continue
            if eqs:
                after = decl[eqs[0] + 1:]
                if after and after[0] == "[":
                    # A lambda held by a namespace- or class-scope variable.
                    var = decl[eqs[0] - 1] if eqs[0] > 0 else "?"
                    yield (start_line, "::".join(scope + [var + " (lambda)"]),
                           tokens[close][1] - start_line + 1)
                head = []
                i = close + 1
                continue
            # A constructor's initialiser list: the parameter list closes before the ':'.
            colon = depth0(decl, lambda tk, k: tk == ":")
            ctor = colon[0] if colon and params_close(decl[: colon[0]]) is not None else None
            prev = decl[-1]
            if ctor is not None and (re.match(r"[A-Za-z_]", prev) or prev == ">"):
                # A member's brace initialiser `x_{...}` in the list, not yet the body.
                head += [i, close]
                i = close + 1
                continue
            if ctor is not None:
                name = function_name(decl, params_close(decl[:ctor]))
            else:
                pclose = params_close(decl)
                if pclose is None:
                    # An initialiser or something unknown: skipped.
                    head = []
                    i = close + 1
                    continue
                name = function_name(decl, pclose)
            yield start_line, "::".join(scope + [name]), tokens[close][1] - start_line + 1
            head = []
            i = close + 1

    yield from scan(0, len(tokens), [])


def tracked_files(root, paths):
    if paths:
        files = []
        for p in paths:
            if os.path.isdir(p):
                for d, _, names in os.walk(p):
                    files += [os.path.join(d, f) for f in sorted(names) if f.endswith(EXTENSIONS)]
            else:
                files.append(p)
        return files
    out = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True,
                         check=True).stdout.split("\n")
    files = []
    for f in out:
        if not f.endswith(EXTENSIONS) or GENERATED.search(f):
            continue
        if EXCLUDED_PARTS.intersection(f.split("/")[:-1]):
            continue
        files.append(os.path.join(root, f))
    return files


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max", type=int, default=150, help="longest function, lines")
    parser.add_argument("--max-file", type=int, default=800, help="longest file, lines")
    parser.add_argument("--list", action="store_true", help="print every function found")
    parser.add_argument("paths", nargs="*", help="files or directories (default: the tree)")
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    findings = 0
    for path in tracked_files(root, args.paths):
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        shown = os.path.relpath(path, root) if not args.paths else path
        lines = len(text.splitlines())
        if lines > args.max_file:
            print(f"{shown}:1: file: {lines} lines (limit {args.max_file})")
            findings += 1
        for line, name, length in analyse(path, text):
            if args.list:
                print(f"{shown}:{line}: {name} {length}")
            if length > args.max:
                print(f"{shown}:{line}: function {name}: {length} lines (limit {args.max})")
                findings += 1
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
