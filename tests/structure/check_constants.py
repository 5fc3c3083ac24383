#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The numbers the bindings copy, checked against the C and C++ definitions.

  check_constants.py SOURCE_DIR

1. ccomm.h against the Python binding (python/src/ccomm/). Every numeric #define and
   every enum member of ccomm.h is read from the header itself (no list here), then:
   - error codes: each CCOMM_E_* has one exception class in _errors._ERRORS, under its
     value, whose docstring starts with its name; no other entry; the module's E_X
     constants equal CCOMM_E_X;
   - enums: a Python IntEnum whose docstring names a ccomm.h enum (`ccomm_status`) has
     exactly its members (CCOMM_ and the members' common prefix taken off) with the
     same values;
   - constants: a module-level name of the binding that is a ccomm.h name without its
     CCOMM_ (OPEN_BATCH, _EMPTY, E_FULL, ROLE_PRODUCER...), or an integer assignment
     whose comment names one (`= 0x1  # CCOMM_INFO_SAFE_VALUE`), has its value;
   - mcap_io/schema.py's AGE_CODES names ccomm_production_age_code's members in order.
2. The Wireshark dissector (integrations/wireshark/ccomm.lua) against the C++ wire
   definitions (src/wire/wire.h, summary.h, src/common/value_type.h, the port and
   EtherType defaults of src/config/config.h): each `local NAME, ... = 1, ...` of
   upper-case names at the top of the file names, in its trailing `-- wire:` comment,
   the C++ constants (or `a | b` of them) it copies, and must equal them; a line of such
   constants without that comment fails. The type table (code, name, size) must be the
   C++ one, and the decode error names those of DecodeErrorName().
Exit 0 if all agree; 1 with one line per difference.
"""
import ast
import os
import re
import sys

NUMBER = r"\(?\s*(-?(?:0[xX][0-9A-Fa-f]+|\d+))[uUlL]*\s*\)?"


def number(text):
    return int(text, 0)


# ---- ccomm.h --------------------------------------------------------------------------
def header_constants(text):
    """({name: value} of every numeric #define and enum member, {enum: [(member, value)]})."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    values, enums = {}, {}
    for name, value in re.findall(r"^\s*#\s*define\s+(CCOMM_\w+)\s+%s\s*$" % NUMBER, text, re.M):
        values[name] = number(value)
    for enum_name, body in re.findall(r"typedef\s+enum\s+(\w+)\s*\{(.*?)\}", text, re.S):
        members, nxt = [], 0
        for item in body.split(","):
            item = item.strip()
            if not item:
                continue
            m = re.match(r"(\w+)\s*(?:=\s*%s)?$" % NUMBER, item)
            if not m:
                sys.exit("check_constants: cannot read enum %s member %r" % (enum_name, item))
            nxt = number(m.group(2)) if m.group(2) else nxt
            members.append((m.group(1), nxt))
            values[m.group(1)] = nxt
            nxt += 1
        enums[enum_name] = members
    return values, enums


def stripped(members):
    """CCOMM_ and the members' common prefix taken off: CCOMM_CLOCK_NONE -> NONE."""
    names = [m for m, _ in members]
    prefix = os.path.commonprefix(names)
    prefix = prefix[:prefix.rfind("_") + 1] if "_" in prefix else ""
    if len(names) == 1:
        prefix = "CCOMM_"
    return [(n[len(prefix):], v) for n, v in members]


def literal(node):
    """The int of an integer literal node (-5 included), else None."""
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        v = literal(node.operand)
        return -v if v is not None else None
    if isinstance(node, ast.Constant) and isinstance(node.value, int) and not isinstance(node.value, bool):
        return node.value
    return None


def assignments(tree):
    """(name, value node, line) for each module-level NAME = ... and A, B = x, y."""
    for stmt in tree.body:
        if not isinstance(stmt, ast.Assign):
            continue
        for target in stmt.targets:
            if isinstance(target, ast.Name):
                yield target.id, stmt.value, stmt.lineno
            elif isinstance(target, ast.Tuple) and isinstance(stmt.value, ast.Tuple) and \
                    len(target.elts) == len(stmt.value.elts):
                for t, v in zip(target.elts, stmt.value.elts):
                    if isinstance(t, ast.Name):
                        yield t.id, v, stmt.lineno


def python_binding(src, errors):
    header = open(os.path.join(src, "src/include/ccomm/ccomm.h"), encoding="utf-8").read()
    values, enums = header_constants(header)
    if not any(n.startswith("CCOMM_E_") for n in values) or not enums:
        sys.exit("check_constants: read no error codes or enums from ccomm.h")
    pkg = os.path.join(src, "python/src/ccomm")
    modules = {}
    for d, _, files in os.walk(pkg):
        for f in sorted(files):
            if f.endswith(".py"):
                path = os.path.join(d, f)
                modules[os.path.relpath(path, src)] = open(path, encoding="utf-8").read()
    checked = 0

    # Error codes: _errors._ERRORS {code: class}, each class's docstring "CCOMM_E_X: ...".
    rel = "python/src/ccomm/_errors.py"
    tree = ast.parse(modules[rel])
    module_ints = {n: literal(v) for n, v, _ in assignments(tree) if literal(v) is not None}
    docs = {c.name: ast.get_docstring(c) or "" for c in tree.body if isinstance(c, ast.ClassDef)}
    table = next((v for n, v, _ in assignments(tree) if n == "_ERRORS"), None)
    if not isinstance(table, ast.Dict):
        errors.append("%s: no _ERRORS dict literal" % rel)
        table = ast.Dict(keys=[], values=[])
    named = set()
    for k, v in zip(table.keys, table.values):
        code = literal(k) if literal(k) is not None else module_ints.get(getattr(k, "id", None))
        cls = getattr(v, "id", "?")
        m = re.match(r"(CCOMM_E_\w+):", docs.get(cls, ""))
        if code is None or not m:
            errors.append("%s: _ERRORS entry %s: no literal code or no 'CCOMM_E_X:' docstring" % (rel, cls))
            continue
        named.add(m.group(1))
        checked += 1
        if values.get(m.group(1)) != code:
            errors.append("%s: %s is %s for %s, ccomm.h says %s" % (rel, cls, code, m.group(1), values.get(m.group(1))))
    for name in sorted(n for n in values if n.startswith("CCOMM_E_")):
        if name not in named:
            errors.append("%s: ccomm.h's %s (%d) has no exception in _ERRORS" % (rel, name, values[name]))

    # Enums named in an IntEnum's docstring; constants by name or by comment.
    seen_enums = set()
    for rel, text in sorted(modules.items()):
        tree = ast.parse(text)
        lines = text.splitlines()
        for cls in (c for c in tree.body if isinstance(c, ast.ClassDef)):
            if not any(getattr(b, "attr", getattr(b, "id", "")) in ("IntEnum", "IntFlag") for b in cls.bases):
                continue
            doc = ast.get_docstring(cls) or ""
            c_enum = next((e for e in re.findall(r"\bccomm_\w+", doc) if e in enums), None)
            if not c_enum:
                errors.append("%s: enum %s names no ccomm.h enum in its docstring" % (rel, cls.name))
                continue
            seen_enums.add(c_enum)
            py = [(n, literal(v)) for n, v, _ in assignments(ast.Module(body=cls.body, type_ignores=[]))]
            want = stripped(enums[c_enum])
            checked += len(want)
            if sorted(py) != sorted(want):
                errors.append("%s: %s is %s; ccomm.h's %s is %s" % (rel, cls.name, dict(py), c_enum, dict(want)))
        for name, node, line in assignments(tree):
            v = literal(node)
            if v is None:
                continue
            c_names = re.findall(r"\bCCOMM_\w+", lines[line - 1].split("#", 1)[1]) \
                if "#" in lines[line - 1] else []
            by_name = "CCOMM_" + name.lstrip("_")
            if by_name in values and by_name not in c_names:
                c_names.append(by_name)
            for c in c_names:
                if c not in values:
                    if c == by_name:
                        continue
                    errors.append("%s:%d: %s names %s, which ccomm.h does not define" % (rel, line, name, c))
                    continue
                checked += 1
                if values[c] != v:
                    errors.append("%s:%d: %s = %d, but ccomm.h's %s is %d" % (rel, line, name, v, c, values[c]))

    # AGE_CODES: the production age codes' names in value order.
    rel = "python/src/ccomm/mcap_io/schema.py"
    codes = next((v for n, v, _ in assignments(ast.parse(modules[rel])) if n == "AGE_CODES"), None)
    want = [n.lower() for n, _ in sorted(stripped(enums["ccomm_production_age_code"]), key=lambda m: m[1])]
    got = [e.value for e in getattr(codes, "elts", [])]
    checked += len(want)
    if got != want or [v for _, v in sorted(enums["ccomm_production_age_code"], key=lambda m: m[1])] != \
            list(range(len(want))):
        errors.append("%s: AGE_CODES is %s; ccomm.h's ccomm_production_age_code gives %s" % (rel, got, want))
    return checked


# ---- wire.h and the dissector ---------------------------------------------------------
def cpp_constants(src):
    """{name: value} of the wire module's constexpr integers and enum members, the value
    types (ValueType kBool...), and config.h's uint16_t defaults (udp_port, ethertype)."""
    values = {}

    def evaluate(expr):
        expr = re.sub(r"(?<=[0-9A-Fa-f])[uU][lL]{0,2}\b", "", expr.strip())
        expr = re.sub(r"\b(k\w+)\b", lambda m: str(values[m.group(1)]) if m.group(1) in values else m.group(1), expr)
        if not re.fullmatch(r"[0-9xXa-fA-F\s|<>()+*-]+", expr):
            return None
        return eval(expr, {"__builtins__": {}})  # digits and operators only (checked above)

    for f in ("src/wire/wire.h", "src/wire/summary.h", "src/common/value_type.h"):
        text = re.sub(r"//[^\n]*", "", open(os.path.join(src, f), encoding="utf-8").read())
        for name, expr in re.findall(r"constexpr\s+[\w:]+\s+(k\w+)\s*=\s*([^;]+);", text):
            v = evaluate(expr)
            if v is not None:
                values[name] = v
        for body in re.findall(r"\benum\b[^{;]*\{([^}]*)\}", text):
            for name, expr in re.findall(r"(k\w+)\s*=\s*([^,]+)", body):
                v = evaluate(expr)
                if v is not None:
                    values[name] = v
    config = open(os.path.join(src, "src/config/config.h"), encoding="utf-8").read()
    for name, v in re.findall(r"uint16_t\s+(\w+)\s*=\s*(0[xX][0-9A-Fa-f]+|\d+)\s*;", config):
        values[name] = number(v)
    return values


def type_table(src):
    """{code: (name, size)} from value_type.h: ValueType's members and ValueTypeSize()."""
    text = open(os.path.join(src, "src/common/value_type.h"), encoding="utf-8").read()
    enum = re.search(r"enum class ValueType[^{]*\{([^}]*)\}", text).group(1)
    names = {number(v): n[1:].lower() for n, v in re.findall(r"(k\w+)\s*=\s*(\d+)", enum)}
    size_fn = re.search(r"ValueTypeSize\(uint8_t code\)\s*\{(.*?)\n\}", text, re.S).group(1)
    sizes = {number(c): number(size) for cases, size in re.findall(r"((?:case\s+\d+:\s*)+)return\s+(\d+);", size_fn)
             for c in re.findall(r"\d+", cases)}
    return {c: (names[c], sizes.get(c)) for c in names}


def dissector(src, errors):
    rel = "integrations/wireshark/ccomm.lua"
    lua = open(os.path.join(src, rel), encoding="utf-8").read()
    cpp = cpp_constants(src)
    checked = 0
    head = lua.split("\nlocal function ", 1)[0]  # the constants come before the first function
    for i, line in enumerate(head.splitlines(), 1):
        m = re.match(r"local\s+([A-Z][A-Z0-9_]*(?:\s*,\s*[A-Z][A-Z0-9_]*)*)\s*=\s*([^-]+?)\s*(?:--\s*(.*))?$", line)
        if not m:
            continue
        names = [n.strip() for n in m.group(1).split(",")]
        nums = [n.strip() for n in m.group(2).split(",")]
        if not all(re.fullmatch(r"0[xX][0-9A-Fa-f]+|\d+", n) for n in nums):
            continue  # not a line of numbers
        wire = re.match(r"wire:\s*(.*)", m.group(3) or "")
        refs = [r.strip() for r in wire.group(1).split(",")] if wire else []
        if len(refs) != len(names) or len(nums) != len(names):
            errors.append("%s:%d: %s: each number needs its C++ constant in a trailing '-- wire: kA, kB' "
                          "comment" % (rel, i, ", ".join(names)))
            continue
        for name, num, ref in zip(names, nums, refs):
            want = 0
            for part in ref.split("|"):
                part = part.strip()
                if part not in cpp:
                    errors.append("%s:%d: %s names %s, which the C++ wire definitions do not define" % (rel, i, name, part))
                    want = None
                    break
                want |= cpp[part]
            checked += 1
            if want is not None and number(num) != want:
                errors.append("%s:%d: %s = %s, but %s is %d (0x%X)" % (rel, i, name, num, ref, want, want))
    types = {number(c): (n, number(s)) for c, n, s in
             re.findall(r'\[(\d+)\]\s*=\s*\{\s*name\s*=\s*"(\w+)",\s*size\s*=\s*(\d+)\s*\}', lua)}
    checked += len(types)
    if types != type_table(src):
        errors.append("%s: TYPES is %s; src/common/value_type.h gives %s" % (rel, types, type_table(src)))
    wire_cpp = open(os.path.join(src, "src/wire/wire.cpp"), encoding="utf-8").read()
    fn = re.search(r"DecodeErrorName\(DecodeError e\)\s*\{(.*?)\n\}", wire_cpp, re.S).group(1)
    cpp_names = [n for n in re.findall(r'return\s+"(\w+)";', fn) if n not in ("ok", "unknown")]
    lua_names = re.search(r"for _, name in ipairs\(\{([^}]*)\}\) do", lua)
    lua_names = re.findall(r'"(\w+)"', lua_names.group(1)) if lua_names else []
    checked += len(cpp_names)
    if lua_names != cpp_names:
        errors.append("%s: decode errors %s; DecodeErrorName() (src/wire/wire.cpp) names %s" % (rel, lua_names, cpp_names))
    return checked


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
    errors = []
    n_py = python_binding(src, errors)
    n_lua = dissector(src, errors)
    for e in errors:
        print("constants: " + e)
    if not errors:
        print("constants: the Python binding agrees with ccomm.h (%d values), the dissector with the wire "
              "definitions (%d values)" % (n_py, n_lua))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
