#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Generates the 20-sim 4C I/O component of one ccomm node from signals.xml.

    gen_4c.py [--node NODE] SIGNALS.XML [NODE] OUTDIR

(`ccomm [--node NODE] gen 20sim4c SIGNALS.XML OUTDIR` runs it.) Without a NODE the node
is $CCOMM_NODE, else the hostname, as for ccommd. Writes to OUTDIR:
  ccomm_4c.h, ccomm_4c.c   ANSI C driver: one port per signal element of the node
  ccomm_4c_component.xml   the component and its ports for the target configuration
  ccomm_4c_ports.txt       the port list, for people

Ports, from the model's point of view:
  inputs   every signal NODE produces or consumes, element by element ("sig", or
           "sig[1]".."sig[n]" for arrays), plus "ccomm_ok": 1 while every input the
           model uses is fresh (0 in the first period, before the driver knows them)
  outputs  every signal NODE produces
The driver reads only signals whose ports the model uses and writes only those it sets.
Call sequence per period: ccomm4c_input(); model with ccomm4c_get()/ccomm4c_set();
ccomm4c_output(). Exit status: 0, or 2 for a configuration the driver cannot serve.
"""
from __future__ import annotations

import re
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

TYPES = {  # name -> (ccomm_type constant, bytes)
    "bool": ("CCOMM_BOOL", 1), "int32": ("CCOMM_INT32", 4), "uint32": ("CCOMM_UINT32", 4),
    "int64": ("CCOMM_INT64", 8), "float": ("CCOMM_FLOAT", 4), "double": ("CCOMM_DOUBLE", 8),
}


class ConfigError(Exception):
    pass


@dataclass
class Signal:
    name: str
    type: str
    count: int
    is_event: bool
    producer: str
    consumers: list[str]
    line: int


def _split(v: str) -> list[str]:
    return [x for x in re.split(r"[\s,]+", v.strip()) if x]


def load(path: Path) -> tuple[list[str], list[Signal]]:
    """Reads nodes and signals; the C++ loader (ccommd --check) is the full validator,
    this checks what the generated code depends on."""
    try:
        # RapidXML (ccommd) accepts "--" inside comments, strict XML parsers do not:
        # drop comments first so both read the same files.
        text = re.sub(r"<!--.*?-->", lambda m: "\n" * m.group(0).count("\n"),
                      path.read_text(encoding="utf-8"), flags=re.S)
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise ConfigError(f"{path}: {e}") from e
    if root.tag != "ccomm":
        raise ConfigError(f"{path}: root element is <{root.tag}>, expected <ccomm>")
    nodes = [n.get("name", "") for n in root.findall("node")]
    signals = []
    for i, s in enumerate(root.findall("signal")):
        name = s.get("name", "")
        where = f"{path}: signal {name or '#' + str(i)}"
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.]*", name):
            raise ConfigError(f"{where}: name must be an identifier")
        t = s.get("type", "double")
        if t not in TYPES:
            raise ConfigError(f"{where}: unknown type '{t}'")
        try:
            count = int(s.get("count", "1"))
        except ValueError as e:
            raise ConfigError(f"{where}: count is not a number") from e
        if count < 1:
            raise ConfigError(f"{where}: count must be at least 1")
        kind = s.get("kind", "state")
        if kind not in ("state", "event"):
            raise ConfigError(f"{where}: kind must be state or event")
        producer = s.get("producer", "")
        if producer not in nodes:
            raise ConfigError(f"{where}: producer '{producer}' is not a <node>")
        signals.append(Signal(name, t, count, kind == "event", producer,
                              _split(s.get("consumers", "")), i))
    return nodes, signals


def ident(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9]", "_", name).upper()


def c_str(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def generate(config: Path, node: str, out: Path) -> None:
    nodes, signals = load(config)
    if node not in nodes:
        raise ConfigError(f"{config}: no node '{node}' (nodes: {', '.join(nodes)})")
    readable = [s for s in signals if s.producer == node or node in s.consumers]
    writable = [s for s in signals if s.producer == node]
    if any(s.name == "ccomm_ok" for s in readable):
        raise ConfigError(f"{config}: a signal named ccomm_ok clashes with the status port")
    if not readable:
        raise ConfigError(f"{config}: node '{node}' produces and consumes no signal")

    sig_index = {s.name: i for i, s in enumerate(readable)}
    in_ports: list[tuple[str, str, int, int]] = []  # (port name, macro, signal index, element)
    out_ports: list[tuple[str, str, int, int]] = []
    for s in readable:
        for e in range(s.count):
            pname = s.name if s.count == 1 else f"{s.name}[{e + 1}]"
            macro = ident(s.name) if s.count == 1 else f"{ident(s.name)}_{e + 1}"
            in_ports.append((pname, macro, sig_index[s.name], e))
            if s in writable:
                out_ports.append((pname, macro, sig_index[s.name], e))
    macros = [p[1] for p in in_ports]
    if len(set(macros)) != len(macros):
        raise ConfigError(f"{config}: two signal names map to the same C identifier")

    out.mkdir(parents=True, exist_ok=True)
    src = config.name
    n_sig = len(readable)

    # ---------------------------------------------------------------- header
    h = [
        "/* SPDX-License-Identifier: Apache-2.0 */",
        f"/* Generated by gen_4c.py from {src} for node '{node}'. Do not edit: regenerate",
        " * with `ccomm gen 20sim4c` when signals.xml changes (the driver refuses to start",
        " * if a signal's type or size no longer matches). */",
        "#ifndef CCOMM_4C_H",
        "#define CCOMM_4C_H",
        "",
        "#ifdef __cplusplus",
        'extern "C" {',
        "#endif",
        "",
        f"#define CCOMM4C_NODE {c_str(node)}",
        f"#define CCOMM4C_NUM_INPUTS {len(in_ports) + 1}",
        f"#define CCOMM4C_NUM_OUTPUTS {len(out_ports)}",
        "",
        "/* Input ports (values the model reads). */",
    ]
    for i, p in enumerate(in_ports):
        h.append(f"#define CCOMM4C_IN_{p[1]} {i} /* {p[0]} */")
    h.append(f"#define CCOMM4C_IN_CCOMM_OK {len(in_ports)} /* 1 while all used inputs are fresh */")
    h.append("")
    h.append("/* Output ports (values the model writes). */")
    for i, p in enumerate(out_ports):
        h.append(f"#define CCOMM4C_OUT_{p[1]} {i} /* {p[0]} */")
    h += [
        "",
        "/* Start-up: attaches to the node's ccommd and checks every signal against the",
        " * generated tables. 0 or a negative ccomm error (the reason is printed). */",
        "int ccomm4c_initialize(void);",
        "/* Start of a period: reads the inputs the model uses. Returns how many of them are",
        " * not fresh (>= 0), or CCOMM_E_RETIRED (-9) when ccommd replaced the segment. */",
        "int ccomm4c_input(void);",
        "/* Value of input port `port` (double, whatever the signal's type). */",
        "double ccomm4c_get(int port);",
        "/* ccomm_status of input port `port` in this period (CCOMM_FRESH = 0, ...). */",
        "int ccomm4c_status(int port);",
        "/* Sets output port `port`; sent by ccomm4c_output(). Integers are rounded and",
        " * saturated, bool is value != 0. */",
        "void ccomm4c_set(int port, double value);",
        "/* End of a period: writes every output signal the model set. Returns the number",
        " * of failed writes (>= 0), or CCOMM_E_RETIRED. */",
        "int ccomm4c_output(void);",
        "void ccomm4c_terminate(void);",
        "/* Port names as in the 4C connect dialog (NULL for a bad index). */",
        "const char* ccomm4c_input_name(int port);",
        "const char* ccomm4c_output_name(int port);",
        "",
        "#ifdef __cplusplus",
        "}",
        "#endif",
        "#endif",
    ]
    (out / "ccomm_4c.h").write_text("\n".join(h) + "\n")

    # ---------------------------------------------------------------- driver
    max_bytes = max(s.count * TYPES[s.type][1] for s in readable)
    rows = []
    for s in readable:
        rows.append(f"    {{{c_str(s.name)}, {TYPES[s.type][0]}, {s.count}u, {s.count * TYPES[s.type][1]}u, "
                    f"{1 if s.is_event else 0}, {1 if s in writable else 0}}},")
    in_rows = [f"    {{{p[2]}, {p[3]}u, {c_str(p[0])}}}," for p in in_ports]
    out_rows = [f"    {{{p[2]}, {p[3]}u, {c_str(p[0])}}}," for p in out_ports] or ["    {-1, 0u, \"\"},"]
    c = f"""/* SPDX-License-Identifier: Apache-2.0 */
/* Generated by gen_4c.py from {src} for node '{node}': 20-sim 4C I/O component that
 * connects model ports to ccomm signals. ANSI C plus <stdint.h>; no allocation and no
 * system call after ccomm4c_initialize() (except ccomm's event doorbell, see ccomm.h). */
#include "ccomm_4c.h"

#include <ccomm/ccomm.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define NSIG {n_sig}
#define MAX_BYTES {max_bytes}
#define EVENT_DRAIN_LIMIT 1024

typedef struct {{
  const char* name;
  int32_t type;
  uint32_t count;
  uint32_t bytes;
  int is_event;
  int writable;
}} sig_info;

typedef struct {{
  int sig;
  uint32_t element;
  const char* name;
}} port_info;

static const sig_info sigs[NSIG] = {{
{chr(10).join(rows)}
}};
static const port_info in_ports[CCOMM4C_NUM_INPUTS - 1 + 1] = {{
{chr(10).join(in_rows)}
    {{-1, 0u, "ccomm_ok"}},
}};
static const port_info out_ports[CCOMM4C_NUM_OUTPUTS + 1] = {{
{chr(10).join(out_rows)}
    {{-1, 0u, ""}},
}};

static ccomm_client* client = NULL;
static ccomm_signal ids[NSIG];
static unsigned char value[NSIG][MAX_BYTES]; /* current value, host layout */
static unsigned char sent[NSIG][MAX_BYTES];  /* output events: last value sent */
static unsigned char scratch[MAX_BYTES];
static int used[NSIG];    /* the model reads it */
static int dirty[NSIG];   /* the model set it this period */
static int sent_once[NSIG];
static int32_t status[NSIG];
static int ok_value = 0;  /* ccomm_ok: 0 until the first complete period */
static unsigned long periods = 0;

static int read_signal(int i) {{
  ccomm_info info;
  int r, k;
  if (sigs[i].is_event) {{
    /* The newest event is the port value; between events the port holds the last one. */
    for (k = 0; k < EVENT_DRAIN_LIMIT; k++) {{
      r = ccomm_read(client, ids[i], scratch, sigs[i].bytes, NULL);
      if (r < 0) return r;
      if (r == CCOMM_EMPTY) break;
      memcpy(value[i], scratch, sigs[i].bytes);
    }}
    status[i] = CCOMM_FRESH;
    return CCOMM_FRESH;
  }}
  r = ccomm_read(client, ids[i], value[i], sigs[i].bytes, &info);
  if (r < 0) return r;
  if (r == CCOMM_NEVER && !(info.flags & CCOMM_INFO_SAFE_VALUE)) memset(value[i], 0, sigs[i].bytes);
  status[i] = r;
  return r;
}}

int ccomm4c_initialize(void) {{
  int i, r, bad = 0;
  r = ccomm_open(CCOMM4C_NODE, 0, &client);
  if (r != 0) {{
    fprintf(stderr, "ccomm4c: cannot attach to node %s: %s\\n", CCOMM4C_NODE, ccomm_strerror(r));
    client = NULL;
    return r;
  }}
  for (i = 0; i < NSIG; i++) {{
    ccomm_signal_desc d;
    ids[i] = ccomm_find(client, sigs[i].name);
    if (ids[i] < 0 || ccomm_describe(client, ids[i], &d) != 0) {{
      fprintf(stderr, "ccomm4c: signal %s is not in the running configuration\\n", sigs[i].name);
      bad = CCOMM_E_NOENT;
      continue;
    }}
    if (d.type != sigs[i].type || d.count != sigs[i].count || d.value_bytes != sigs[i].bytes ||
        d.is_event != sigs[i].is_event) {{
      fprintf(stderr, "ccomm4c: signal %s changed type or size since this driver was generated\\n",
              sigs[i].name);
      bad = CCOMM_E_TYPE;
    }}
    if (sigs[i].writable && !d.produced_here) {{
      fprintf(stderr, "ccomm4c: signal %s is no longer produced by node %s\\n", sigs[i].name,
              CCOMM4C_NODE);
      bad = CCOMM_E_PERM;
    }}
    used[i] = dirty[i] = sent_once[i] = 0;
    status[i] = CCOMM_NEVER;
  }}
  if (bad) {{
    fprintf(stderr, "ccomm4c: regenerate the component (ccomm gen 20sim4c) for this signals.xml\\n");
    ccomm_close(client);
    client = NULL;
    return bad;
  }}
  periods = 0;
  ok_value = 0;
  return 0;
}}

int ccomm4c_input(void) {{
  int i, r, not_fresh = 0, any = 0;
  if (!client) return CCOMM_E_INVAL;
  for (i = 0; i < NSIG; i++) {{
    if (!used[i]) continue;
    r = read_signal(i);
    if (r == CCOMM_E_RETIRED) return r;
    any = 1;
    if (r != CCOMM_FRESH) not_fresh++;
  }}
  /* The first period has not seen which inputs the model uses: report not ok. */
  ok_value = (periods > 0 && any && not_fresh == 0) ? 1 : 0;
  periods++;
  return not_fresh;
}}

static double element_get(int i, uint32_t e) {{
  const unsigned char* p = value[i];
  switch (sigs[i].type) {{
    case CCOMM_BOOL: return p[e] ? 1.0 : 0.0;
    case CCOMM_INT32: {{ int32_t v; memcpy(&v, p + 4 * e, 4); return (double)v; }}
    case CCOMM_UINT32: {{ uint32_t v; memcpy(&v, p + 4 * e, 4); return (double)v; }}
    case CCOMM_INT64: {{ int64_t v; memcpy(&v, p + 8 * e, 8); return (double)v; }}
    case CCOMM_FLOAT: {{ float v; memcpy(&v, p + 4 * e, 4); return (double)v; }}
    default: {{ double v; memcpy(&v, p + 8 * e, 8); return v; }}
  }}
}}

double ccomm4c_get(int port) {{
  int i;
  if (port < 0 || port >= CCOMM4C_NUM_INPUTS || !client) return 0.0;
  if (port == CCOMM4C_IN_CCOMM_OK) return ok_value ? 1.0 : 0.0;
  i = in_ports[port].sig;
  if (!used[i]) {{
    /* First use: read it now; from the next period on ccomm4c_input() reads it. */
    used[i] = 1;
    if (read_signal(i) < 0) status[i] = CCOMM_NEVER;
  }}
  return element_get(i, in_ports[port].element);
}}

int ccomm4c_status(int port) {{
  if (port < 0 || port >= CCOMM4C_NUM_INPUTS) return CCOMM_E_INVAL;
  if (port == CCOMM4C_IN_CCOMM_OK) return ok_value ? CCOMM_FRESH : CCOMM_STALE;
  return status[in_ports[port].sig];
}}

/* Nearest integer, saturated; NaN gives 0: an output never wraps around. */
static double clampr(double v, double lo, double hi) {{
  if (v != v) return 0.0;
  v = floor(v + 0.5);
  return v < lo ? lo : (v > hi ? hi : v);
}}

void ccomm4c_set(int port, double v) {{
  int i;
  uint32_t e;
  unsigned char* p;
  if (port < 0 || port >= CCOMM4C_NUM_OUTPUTS) return;
  i = out_ports[port].sig;
  e = out_ports[port].element;
  p = value[i];
  switch (sigs[i].type) {{
    case CCOMM_BOOL: p[e] = (v != 0.0 && v == v) ? 1 : 0; break;
    case CCOMM_INT32: {{ int32_t x = (int32_t)clampr(v, -2147483648.0, 2147483647.0); memcpy(p + 4 * e, &x, 4); break; }}
    case CCOMM_UINT32: {{ uint32_t x = (uint32_t)clampr(v, 0.0, 4294967295.0); memcpy(p + 4 * e, &x, 4); break; }}
    case CCOMM_INT64: {{ int64_t x = (int64_t)clampr(v, -9223372036854775808.0, 9223372036854774784.0); memcpy(p + 8 * e, &x, 8); break; }}
    case CCOMM_FLOAT: {{ float x = (float)v; memcpy(p + 4 * e, &x, 4); break; }}
    default: memcpy(p + 8 * e, &v, 8); break;
  }}
  dirty[i] = 1;
}}

int ccomm4c_output(void) {{
  int i, r, failed = 0;
  if (!client) return CCOMM_E_INVAL;
  for (i = 0; i < NSIG; i++) {{
    if (!dirty[i]) continue;
    dirty[i] = 0;
    /* Events are sent when the value changes, states every period. */
    if (sigs[i].is_event && sent_once[i] && memcmp(value[i], sent[i], sigs[i].bytes) == 0) continue;
    r = ccomm_write(client, ids[i], value[i], sigs[i].bytes);
    if (r == CCOMM_E_RETIRED) return r;
    if (r < 0) {{
      failed++;
      continue;
    }}
    memcpy(sent[i], value[i], sigs[i].bytes);
    sent_once[i] = 1;
  }}
  return failed;
}}

void ccomm4c_terminate(void) {{
  if (client) ccomm_close(client);
  client = NULL;
}}

const char* ccomm4c_input_name(int port) {{
  return (port >= 0 && port < CCOMM4C_NUM_INPUTS) ? in_ports[port].name : NULL;
}}

const char* ccomm4c_output_name(int port) {{
  return (port >= 0 && port < CCOMM4C_NUM_OUTPUTS) ? out_ports[port].name : NULL;
}}
"""
    (out / "ccomm_4c.c").write_text(c)

    # ---------------------------------------------------------------- component description
    def esc(s: str) -> str:
        return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")

    x = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f"<!-- Generated by gen_4c.py from {esc(src)} for node '{esc(node)}'. The ccomm I/O",
        "     component for a 20-sim 4C target configuration: merge the <COMPONENT> into the",
        "     COMPONENTS section of the target's tcf and add ccomm_4c.c/.h and -lccomm to its",
        "     compile step. See docs/integrations/20sim.md. -->",
        "<COMPONENTS>",
        "  <COMPONENT>",
        "    <NAME>ccomm</NAME>",
        f"    <DESCRIPTION>ccomm signals of node {esc(node)}</DESCRIPTION>",
        "    <FILES>ccomm_4c.c;ccomm_4c.h</FILES>",
        "    <LIBRARIES>ccomm;m</LIBRARIES>",
        "    <INITIALIZE>ccomm4c_initialize();</INITIALIZE>",
        "    <PRE_CALCULATE>ccomm4c_input();</PRE_CALCULATE>",
        "    <POST_CALCULATE>ccomm4c_output();</POST_CALCULATE>",
        "    <TERMINATE>ccomm4c_terminate();</TERMINATE>",
        "    <PORTS>",
    ]
    for i, p in enumerate(in_ports):
        x.append(f"      <PORT><NAME>{esc(p[0])}</NAME><DIRECTION>INPUT</DIRECTION>"
                 f"<ACCESS>ccomm4c_get({i})</ACCESS></PORT>")
    x.append(f"      <PORT><NAME>ccomm_ok</NAME><DIRECTION>INPUT</DIRECTION>"
             f"<ACCESS>ccomm4c_get({len(in_ports)})</ACCESS></PORT>")
    for i, p in enumerate(out_ports):
        x.append(f"      <PORT><NAME>{esc(p[0])}</NAME><DIRECTION>OUTPUT</DIRECTION>"
                 f"<ACCESS>ccomm4c_set({i}, %VALUE%)</ACCESS></PORT>")
    x += ["    </PORTS>", "  </COMPONENT>", "</COMPONENTS>"]
    (out / "ccomm_4c_component.xml").write_text("\n".join(x) + "\n")

    lines = [f"ccomm 20-sim 4C component for node {node} (from {src})", "",
             f"Model inputs ({len(in_ports) + 1}):"]
    lines += [f"  {i:4d}  {p[0]}" for i, p in enumerate(in_ports)]
    lines += [f"  {len(in_ports):4d}  ccomm_ok", "", f"Model outputs ({len(out_ports)}):"]
    lines += [f"  {i:4d}  {p[0]}" for i, p in enumerate(out_ports)]
    (out / "ccomm_4c_ports.txt").write_text("\n".join(lines) + "\n")


def main(argv: list[str]) -> int:
    import argparse
    import os
    import socket

    ap = argparse.ArgumentParser(prog="gen_4c.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--node", help="node to generate for (default: $CCOMM_NODE, else hostname)")
    ap.add_argument("args", nargs="+", metavar="SIGNALS.XML [NODE] OUTDIR")
    a = ap.parse_args(argv[1:])
    if len(a.args) == 3:
        config, node, outdir = a.args
        if a.node and a.node != node:
            ap.error(f"--node {a.node} and NODE {node} disagree")
    elif len(a.args) == 2:
        config, outdir = a.args
        node = a.node or os.environ.get("CCOMM_NODE") or socket.gethostname()
    else:
        ap.error("expected SIGNALS.XML [NODE] OUTDIR")
    try:
        generate(Path(config), node, Path(outdir))
    except (ConfigError, OSError) as e:
        print(f"gen_4c: {e}", file=sys.stderr)
        return 2
    print(f"gen_4c: node {node}: wrote ccomm_4c.c, ccomm_4c.h, ccomm_4c_component.xml, "
          f"ccomm_4c_ports.txt to {outdir}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
