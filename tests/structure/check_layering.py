#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The core's layering, checked on the sources and on the built libraries.

  check_layering.py SOURCE_DIR BUILD_DIR

- store/ and wire/ are bottom modules: their files include only the platform layer
  (common/), their own module and system headers;
- their static libraries use no symbol that config, daemon or client define;
- libccomm.so (the client library every application loads) carries no XML parser:
  no RapidXML, no configuration parser, no config library symbol, exports nothing but
  the C API (ccomm_*), and needs no library beyond the C/C++ runtime;
- the applications of the public API (the CLI, tools, the FMU runner, the ROS 2 bridge)
  include nothing of config, daemon, store, wire, client or common: ccomm.h/ccomm.hpp
  only, the platform layer's part for programs (common/public/platform_app.h: real-time set-up,
  sleeps, the exclusive lock, segment names), and a program that owns an extension
  section of signals.xml (the bridge's <ros2>) the configuration's public interface
  config/public/outline.h: public interfaces are marked by place (a module's public/
  folder), every other header of the core is private; a public interface itself includes
  standard headers only;
- OS calls the platform layer wraps (shared memory, memory locking, scheduling, CPU
  affinity, sleeping) are made only in its units, src/common/platform/: nowhere else in
  the tree, tests, tools, integrations, bench and Python included (FORBIDDEN_CALLS;
  applications use ccomm.h's ccomm_realtime_setup and ccomm_sleep_until), but for the
  programs of OS_CALL_EXCEPTIONS;
- ccommd (src/daemon/) is rooms (ROOMS): each a folder with a README.md that says what it
  owns, no source file outside them; a room's units include only the rooms it may use
  (its tests aside); a room's platform code is in its posix/ and windows/ folders, and its
  portable units include no OS header (PORTABLE_OS_HEADERS);
- no two source files under src/ share a name (two system_view.cpp once meant two
  different things), except the platform units (src/common/platform/, and a room's posix/
  and windows/ units of one interface) and each program's main.cpp;
- signals.xml has one parser (src/config/): no other code uses an XML parser on it
  (tools read `ccommd --check FILE --json`), and the value types' names are tabled once
  (src/common/value_type.h; ccomm_type_name() gives them out).
Each exception is listed below with its reason.
Exit 0 if all hold; 1 with one line per violation.
"""
import os
import re
import subprocess
import sys

BOTTOM = {"store": {"store", "common"}, "wire": {"wire", "common"}}
UPPER = ("config", "daemon", "client")
APPLICATIONS = ("cli", "tools", "fmu", "ros2")
INTERNALS = {"config", "daemon", "store", "wire", "client", "common"}
# (file, include): why it is allowed for now (none: keep it that way).
APPLICATION_INCLUDES = {}
# Public interfaces of internal modules are marked by place: a module's public/ folder
# (src/config/public/outline.h: the configuration as the owner of an extension section
# reads it; src/common/public/platform_app.h: the platform layer's part for programs).
# Every other header of an internal module is private to the core. No list to keep.
PUBLIC_FOLDER = "public"


def is_public_interface(include):
    parts = include.split("/")
    return len(parts) == 3 and parts[0] in INTERNALS and parts[1] == PUBLIC_FOLDER and parts[2].endswith(".h")


def public_interface_headers(src):
    return sorted("%s/%s/%s" % (m, PUBLIC_FOLDER, f) for m in sorted(INTERNALS)
                  if os.path.isdir(os.path.join(src, "src", m, PUBLIC_FOLDER))
                  for f in os.listdir(os.path.join(src, "src", m, PUBLIC_FOLDER)) if f.endswith(".h"))


# OS calls only the platform layer's units (src/common/platform/) make: the POSIX calls
# and their Windows counterparts. Anywhere else under src/ a call of one fails the test
# (comments and string literals aside); use common/platform.h or common/public/platform_app.h.
PLATFORM_DIR = "src/common/platform/"
FORBIDDEN_CALLS = ("shm_open", "shm_unlink", "mlockall", "munlockall", "sched_setscheduler", "sched_setaffinity",
                   "pthread_setschedparam", "pthread_setaffinity_np", "nanosleep", "clock_nanosleep", "flock",
                   "SetThreadPriority", "SetThreadAffinityMask", "SetProcessWorkingSetSize", "CreateFileMapping", "CreateFileMappingA",
                   "CreateFileMappingW", "OpenFileMapping", "OpenFileMappingA", "OpenFileMappingW")
FORBIDDEN_CALL = re.compile(r"(?<![\w.>:])(?:::)?(%s)\s*\(" % "|".join(FORBIDDEN_CALLS))
# Programs outside src/ that make such calls themselves, and why they may.
OS_CALL_EXCEPTIONS = {
    "bench/bench_common.h": "the bench's platform layer for its floor and peer programs, which link nothing "
                            "of ccomm (a floor measures the OS alone, a peer runs as its own users run it)",
    "bench/peers/common/src/lib.rs": "the Rust peers' counterpart of bench/bench_common.h",
    "bench/txtime/txtime_spread.c": "a probe of the kernel's SO_TXTIME, nothing of ccomm in it: it sleeps on "
                                    "CLOCK_REALTIME, which ccomm's API has no call for",
    "tests/fmu/bare_loop.c": "the floor of ccomm-fmu's jitter: the same periodic loop with nothing of ccomm",
    "tests/reliability/garbage.c": "writes over a node's segment as a buggy client would, past libccomm: it "
                                   "maps the segment itself",
    "tests/reliability/flood.c": "forges frames at a socket as an attacker would; links nothing of ccomm",
    "tests/ros2/bench/latency_probe.c": "Cyclone DDS alone, the bridge's peer figure; links nothing of ccomm",
    "tests/syscalls/syscount.c": "its pauses must be relative: under board_clock.so the clock ccomm_now() "
                                 "reads is shifted, so an absolute deadline on it would be wrong",
}
C_CODE = (".c", ".cc", ".cpp", ".h", ".hpp")
# Python: comments and string literals are not code; a call is a name followed by "(",
# also as an attribute (os.sched_setscheduler, ctypes.CDLL(None).mlockall). flock is
# left out: a Python tool's lock of its own file (qemu-tests/lib/vmctl.py) is no node lock.
PY_NOT_CODE = re.compile(r'"""(?:.|\n)*?"""|\'\'\'(?:.|\n)*?\'\'\'|#[^\n]*|"(?:\\.|[^"\\\n])*"|'
                         r"'(?:\\.|[^'\\\n])*'")
PY_FORBIDDEN_CALL = re.compile(r"(?<!\w)(%s)\s*\(" % "|".join(c for c in FORBIDDEN_CALLS if c != "flock"))
# Comments, string and character literals (raw strings first): what is not code.
NOT_CODE = re.compile(r'R"([^(\s]*)\((?:.|\n)*?\)\1"|//[^\n]*|/\*(?:.|\n)*?\*/|"(?:\\.|[^"\\\n])*"|'
                      r"'(?:\\.|[^'\\\n])*'")
CODE = (".py", ".lua", ".c", ".cc", ".cpp", ".h", ".hpp", ".js", ".ts")
XML_PARSERS = re.compile(r"ElementTree|xml\.dom|\blxml\b|rapidxml|\bexpat\b|xml_attr\(")
TYPE_NAMES = ("bool", "int32", "uint32", "int64", "float", "double")
# Files that spell out every type name, and why that is no second table.
TYPE_NAME_TABLES = {
    "src/common/value_type.h": "the table",
    "integrations/wireshark/ccomm.lua": "decodes the wire's type codes inside Wireshark, without libccomm "
                                        "(docs/protocol.md \"Types\")",
    "scripts/wire_vectors.py": "writes the protocol's test vectors from docs/protocol.md, independently of "
                               "the C++ encoder",
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
# ccommd's rooms (src/daemon/README.md) and the rooms each may include.
ROOMS = {
    "engine": {"net", "clock", "security"},
    "net": set(),
    "clock": set(),
    "security": set(),
    "service": {"engine", "net", "clock", "security"},
}
PLATFORM_FOLDERS = ("posix", "windows")
# OS headers a room's portable units may not include (<sys/types.h>, a C type header on
# every platform, may be): their code belongs in the room's posix/ or windows/ folder.
OS_HEADER = re.compile(r'^\s*#\s*include\s*<(sys/(?!types\.h)[\w/]+\.h|unistd\.h|linux/[\w/]+\.h|arpa/\w+\.h|'
                       r'net/\w+\.h|netinet/\w+\.h|ifaddrs\.h|fcntl\.h|signal\.h|poll\.h|dlfcn\.h|sched\.h|'
                       r'syslog\.h|pwd\.h|grp\.h|windows\.h|winsock2\.h|ws2tcpip\.h|iphlpapi\.h|mswsock\.h)>', re.M)


def nm(path, *flags, types="TDBRWVtdbrwv"):
    """Symbol names of `path` whose nm type letter is in `types` (undefined ones: "U")."""
    out = subprocess.run(["nm", "-C", *flags, path], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                         text=True, check=True).stdout
    syms = set()
    for line in out.splitlines():
        parts = line.split(None, 2)
        if len(parts) == 3 and parts[1] in types:
            syms.add(parts[2])
        elif len(parts) == 2 and parts[0] == "U" and "U" in types:
            syms.add(parts[1])
    return syms


# Symbols a sanitizer or the toolchain puts into every shared object.
TOOLCHAIN = ("_init", "_fini", "__bss_start", "_edata", "_end", "__asan", "__tsan", "__ubsan", "__sanitizer",
             "__odr_asan", "___asan", "__lsan")


def library(build, module, name):
    path = os.path.join(build, "src", module, name)
    if not os.path.exists(path):
        sys.exit("check_layering: %s not built (build the whole tree first)" % path)
    return path


def tracked_code(src, extra=()):
    """Source files of the tree (git's list when it is a checkout), relative to `src`."""
    r = subprocess.run(["git", "-C", src, "ls-files"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    if r.returncode == 0 and r.stdout:
        names = r.stdout.split("\n")
    else:
        names = [os.path.relpath(os.path.join(d, f), src) for d, _, fs in os.walk(src) for f in fs
                 if "/build" not in d and "/." not in d]
    return sorted(n for n in names if n.endswith(CODE + tuple(extra)) and os.path.isfile(os.path.join(src, n)))


def one_parser_one_table(src, errors):
    """No XML parser on signals.xml outside src/config/; the type names tabled once
    (tests excepted: they may spell names out to check them)."""
    for name in tracked_code(src):
        text = open(os.path.join(src, name), encoding="utf-8", errors="replace").read()
        if name == "tests/structure/check_layering.py":
            continue  # names the parsers it looks for
        if not name.startswith("src/config/") and XML_PARSERS.search(text) and \
                re.search(r"signals\.xml|<signal\b", text):
            errors.append("%s parses signals.xml with an XML parser (read `ccommd --check FILE --json`: "
                          "src/config/ is its one parser)" % name)
        if name.startswith("tests/") or "_test." in name or name in TYPE_NAME_TABLES:
            continue
        if all(re.search(r"[\"']%s[\"']" % t, text) for t in TYPE_NAMES):
            errors.append("%s tables the type names again (use ccomm_type_name(), or "
                          "SignalType.type_name in Python)" % name)


def application_includes(src, errors):
    for app in APPLICATIONS:
        adir = os.path.join(src, "src", app)
        for fname in sorted(os.listdir(adir)):
            if not fname.endswith((".h", ".cpp", ".c")):
                continue
            rel = "src/%s/%s" % (app, fname)
            text = open(os.path.join(adir, fname), encoding="utf-8").read()
            for inc in INCLUDE.findall(text):
                if inc.split("/")[0] in INTERNALS and "/" in inc and (rel, inc) not in APPLICATION_INCLUDES \
                        and not is_public_interface(inc):
                    errors.append('%s includes "%s": applications use the public API (ccomm/ccomm.h) only'
                                  % (rel, inc))


def platform_unit(name):
    """For a unit in a posix/ or windows/ folder: the folder above it and its name (the
    interface it implements), else None."""
    parts = name.split("/")
    if len(parts) >= 3 and parts[-2] in PLATFORM_FOLDERS:
        return "/".join(parts[:-2]), parts[-1]
    return None


def unique_file_names(src, errors):
    """A file's name says what it is: one name, one file (per-platform units excepted: the
    same interface in src/common/platform/posix/ and .../windows/, or in a room's)."""
    seen = {}
    for name in tracked_code(src):
        if not name.startswith("src/") or name.startswith("src/common/platform/") or \
                os.path.basename(name) == "main.cpp":
            continue
        seen.setdefault(os.path.basename(name), []).append(name)
    for base, names in sorted(seen.items()):
        units = {platform_unit(n) for n in names}
        if len(names) > 1 and None not in units and len(units) == 1:
            continue  # one interface, one unit per platform folder
        if len(names) > 1:
            errors.append("%s: %d files share the name (%s): name each after what it is"
                          % (base, len(names), ", ".join(names)))


def os_calls_in_platform_layer(src, errors):
    """The calls of FORBIDDEN_CALLS only in src/common/platform/, in the whole tree (C, C++,
    Rust and Python: os.sched_setscheduler and a ctypes mlockall count too), but for the
    programs of OS_CALL_EXCEPTIONS."""
    for name in tracked_code(src, extra=(".rs",)):
        if name.startswith(PLATFORM_DIR) or name in OS_CALL_EXCEPTIONS:
            continue
        if name.endswith(C_CODE + (".rs",)):
            not_code, call = NOT_CODE, FORBIDDEN_CALL
        elif name.endswith(".py"):
            not_code, call = PY_NOT_CODE, PY_FORBIDDEN_CALL
        else:
            continue
        text = open(os.path.join(src, name), encoding="utf-8", errors="replace").read()
        code = not_code.sub(lambda m: "\n" * m.group(0).count("\n"), text)  # keeps line numbers
        for m in call.finditer(code):
            errors.append("%s:%d calls %s(): an OS call the platform layer wraps (in the core common/platform.h "
                          "and common/public/platform_app.h, units in %s; for an application ccomm.h's "
                          "ccomm_realtime_setup and ccomm_sleep_until, in Python ccomm.realtime_setup)"
                          % (name, code.count("\n", 0, m.start()) + 1, m.group(1), PLATFORM_DIR))


# Folders of src/ no rule above is about, and why.
OTHER_FOLDERS = {"common": "the platform layer (FORBIDDEN_CALLS) and shared basics: every module may use it",
                 "include": "the public API (ccomm/ccomm.h, ccomm.hpp)",
                 "testing": "test helpers for the unit tests (configurations, documents)"}


def every_folder_known(src, errors):
    """Every folder of src/ is a module a rule above is about (a new one must be placed)."""
    known = set(BOTTOM) | set(UPPER) | set(APPLICATIONS) | set(OTHER_FOLDERS)
    for entry in sorted(os.listdir(os.path.join(src, "src"))):
        if os.path.isdir(os.path.join(src, "src", entry)) and entry not in known:
            errors.append("src/%s/ is in no layer of tests/structure/check_layering.py (BOTTOM, UPPER, "
                          "APPLICATIONS, OTHER_FOLDERS): say where it belongs" % entry)


def daemon_rooms(src, errors):
    """ccommd's rooms: the folders of ROOMS, each with its README.md; includes between
    rooms as ROOMS allows (tests and their fixtures may include any room); no OS header
    in a portable unit; platform folders only inside a room."""
    ddir = os.path.join(src, "src", "daemon")
    for entry in sorted(os.listdir(ddir)):
        path = os.path.join(ddir, entry)
        if os.path.isdir(path):
            if entry not in ROOMS:
                errors.append("src/daemon/%s/ is no room of ROOMS (tests/structure/check_layering.py): add it "
                              "with what it may use, and to src/daemon/README.md" % entry)
            elif not os.path.isfile(os.path.join(path, "README.md")):
                errors.append("src/daemon/%s/ has no README.md saying what the room owns" % entry)
        elif entry.endswith(C_CODE):
            errors.append("src/daemon/%s is in no room: put it in the room whose job it is" % entry)
    for room in sorted(ROOMS):
        if not os.path.isdir(os.path.join(ddir, room)):
            errors.append("src/daemon/%s/ (a room of ROOMS) is missing" % room)
            continue
        for root, dirs, files in os.walk(os.path.join(ddir, room)):
            rel_dir = os.path.relpath(root, ddir).replace(os.sep, "/")
            for d in dirs:
                if d not in PLATFORM_FOLDERS and not d.endswith("_corpus"):
                    errors.append("src/daemon/%s/%s/: a room holds its units and posix/, windows/ only"
                                  % (rel_dir, d))
            platform = rel_dir.split("/")[-1] in PLATFORM_FOLDERS
            for fname in sorted(files):
                if not fname.endswith(C_CODE):
                    continue
                rel = "src/daemon/%s/%s" % (rel_dir, fname)
                text = open(os.path.join(root, fname), encoding="utf-8").read()
                test = fname.endswith("_test.cpp") or fname.endswith(("_fixture.h", "_test_util.h"))
                if not platform and not test:
                    for m in OS_HEADER.finditer(text):
                        errors.append("%s:%d includes <%s>: OS code of a room is in its posix/ or windows/ folder"
                                      % (rel, text.count("\n", 0, m.start()) + 1, m.group(1)))
                if test:
                    continue
                for inc in INCLUDE.findall(text):
                    parts = inc.split("/")
                    if parts[0] != "daemon" or len(parts) < 3:
                        continue
                    other = parts[1]
                    if other != room and other not in ROOMS[room]:
                        errors.append('%s includes "%s": room %s may use %s (ROOMS)'
                                      % (rel, inc, room, ", ".join(sorted(ROOMS[room])) or "no other room"))
                    if len(parts) > 3 and parts[2] in PLATFORM_FOLDERS and other != room:
                        errors.append('%s includes "%s": a room\'s platform code is its own' % (rel, inc))


def public_interfaces(src, errors):
    """A public interface is public only if it pulls in no internals."""
    headers = public_interface_headers(src)
    if not headers:
        errors.append("no src/MODULE/%s/ header found: the public interfaces moved?" % PUBLIC_FOLDER)
    for header in headers:
        text = open(os.path.join(src, "src", header), encoding="utf-8").read()
        for inc in INCLUDE.findall(text):
            errors.append('src/%s includes "%s": a public interface includes standard headers only'
                          % (header, inc))


def main():
    if len(sys.argv) != 3 or not os.path.isdir(sys.argv[1]) or not os.path.isdir(sys.argv[2]):
        sys.stderr.write("usage: check_layering.py SOURCE_DIR BUILD_DIR (a configured and built tree, "
                         "e.g. build/release)\n")
        return 2
    src, build = sys.argv[1], sys.argv[2]
    errors = []
    application_includes(src, errors)
    public_interfaces(src, errors)
    os_calls_in_platform_layer(src, errors)
    unique_file_names(src, errors)
    daemon_rooms(src, errors)
    every_folder_known(src, errors)
    one_parser_one_table(src, errors)
    # 1. Includes of the bottom modules.
    for module, allowed in BOTTOM.items():
        mdir = os.path.join(src, "src", module)
        for fname in sorted(os.listdir(mdir)):
            if not fname.endswith((".h", ".cpp")) or fname.endswith("_test.cpp") or fname.startswith("fuzz_"):
                continue  # tests and fuzz drivers may build segments/configs to exercise the module
            text = open(os.path.join(mdir, fname), encoding="utf-8").read()
            for inc in INCLUDE.findall(text):
                top = inc.split("/")[0] if "/" in inc else module
                if top not in allowed:
                    errors.append('src/%s/%s includes "%s": %s may depend only on %s' %
                                  (module, fname, inc, module, ", ".join(sorted(allowed))))
    # 2. Symbols the bottom libraries use that upper modules define.
    defined_above = {}
    for module, lib in (("config", "libccomm_config.a"), ("daemon", "libccomm_daemon.a"),
                        ("daemon", "libccomm_segment_builder.a")):
        # Strong global definitions only: inline functions and templates from shared
        # headers (weak in unoptimised builds) belong to nobody.
        for s in nm(library(build, module, lib), "--defined-only", types="TDBR"):
            defined_above[s] = module
    client_so = os.path.join(build, "lib", "libccomm.so")
    objdir = os.path.join(build, "src", "client", "CMakeFiles", "ccomm.dir")
    for root, _, files in os.walk(objdir):
        for f in files:
            if f.endswith(".o"):
                for s in nm(os.path.join(root, f), "--defined-only", types="TDBR"):
                    defined_above.setdefault(s, "client")
    for module, lib in (("store", "libccomm_store.a"), ("wire", "libccomm_wire.a")):
        for s in sorted(nm(library(build, module, lib), "--undefined-only", types="U")):
            if s in defined_above:
                errors.append("%s uses %s from %s" % (lib, s, defined_above[s]))
    # 3. libccomm.so without the parser.
    every = nm(client_so)
    for s in sorted(every):
        if "rapidxml" in s or "config_detail" in s or "LoadConfig" in s or "ParseConfig" in s or "SystemConfig" in s:
            errors.append("libccomm.so carries %s (the configuration parser belongs to ccommd)" % s)
    config_syms = nm(library(build, "config", "libccomm_config.a"), "--defined-only", types="TDBR")
    shared = sorted(s for s in config_syms & every if not s.startswith(("std::", "__", "operator", "typeinfo", "vtable")))
    for s in shared[:20]:
        errors.append("libccomm.so carries %s from libccomm_config.a" % s)
    exported = nm(client_so, "-D", "--defined-only", types="TDBRWVi")
    foreign = sorted(s for s in exported if not s.startswith("ccomm_") and not s.startswith(TOOLCHAIN))
    for s in foreign[:20]:
        errors.append("libccomm.so exports %s (only the C API, ccomm_*, is public)" % s)
    needed = subprocess.run(["readelf", "-d", client_so], stdout=subprocess.PIPE, text=True, check=True).stdout
    for lib in re.findall(r"\(NEEDED\).*\[(.+)\]", needed):
        if not re.match(r"lib(c|m|rt|pthread|dl|stdc\+\+|gcc_s|asan|ubsan|tsan)\.so", lib) and not lib.startswith("ld-linux"):
            errors.append("libccomm.so needs %s (only the C/C++ runtime is expected)" % lib)
    for e in errors:
        print("layering: " + e)
    if not errors:
        print("layering: store and wire are bottom modules; libccomm.so carries no configuration parser; "
              "applications use the public API (and config/public/outline.h, common/public/platform_app.h); OS calls of the "
              "platform layer only in its units; ccommd's rooms as ROOMS allows; one file per name; one parser of signals.xml, one table of type names")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
