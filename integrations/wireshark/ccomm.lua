-- SPDX-License-Identifier: Apache-2.0
-- Wireshark dissector for ccomm frames (wire format v2, docs/protocol.md), on raw
-- Ethernet (EtherType 0x88B5) and UDP (port 47800, plus a heuristic for other ports).
--
--   tshark -X lua_script:ccomm.lua -r capture.pcap -O ccomm
--   cp ccomm.lua ~/.local/lib/wireshark/plugins/      (Wireshark and tshark load it)
--
-- One file on purpose (about 600 lines): installing it is copying it, and a Lua plugin
-- split into modules would need Wireshark's package path set up on every machine.
--
-- It checks every frame the way the receiver's DecodeHeader() does, in the same order,
-- and raises one expert info per problem ("bad_entry: entry 0: unknown type 7"); the
-- first one, which is what ccommd would count, is also the field ccomm.decode_error.
-- With the preference ccomm.config (the system's configuration as `ccommd --check
-- signals.xml --json > system.json` writes it) it names nodes and signals, checks
-- config_hash against the configuration's hash (receiver rule 4, config_mismatch) and flags entries
-- that do not match the configuration (receiver rule 6, bad_signal).
-- Documentation: docs/integrations/wireshark.md.

local ccomm = Proto("ccomm", "ccomm signal frames")

-- The wire format's constants, each with the C++ definition it copies (src/wire/wire.h,
-- summary.h; tests/structure/check_constants.py holds them equal).
local HEADER, ENTRY_HEADER, TAG_SIZE = 32, 24, 16  -- wire: kHeaderSize, kEntryHeaderSize, kAuthTagSize
local MAX_FRAME, ETH_MIN_PAYLOAD = 1472, 46  -- wire: kMaxFrameSize, kEthMinPayload
local MAGIC, VERSION = 0x43434D57, 2  -- wire: kMagic, kVersion
local F_HEARTBEAT, F_AUTH, F_SUMMARY, F_KNOWN = 0x01, 0x02, 0x04, 0x07  -- wire: kFlagHeartbeat, kFlagAuth, kFlagSummary, kFlagHeartbeat | kFlagAuth | kFlagSummary
-- node summary body (protocol.md "Node summary"): head, record, records per part
local S_HEAD, S_RECORD, S_MAX = 80, 24, 56  -- wire: kSummaryHeadSize, kSummaryRecordSize, kSummaryMaxRecords
local R_STALE, R_NEVER, R_KNOWN = 0x01, 0x02, 0x03  -- wire: kRecordStale, kRecordNever, kRecordStale | kRecordNever
local CLOCK_STATES, NO_AGE = 4, 0xFFFFFFFF  -- wire: kSummaryClockStates, kSummaryNoAge
local E_EVENT, E_FRAGMENT, E_KNOWN = 0x01, 0x02, 0x03  -- wire: kEntryEvent, kEntryFragment, kEntryEvent | kEntryFragment
-- fragment sub-header; largest fragmented value
local FRAGMENT_HEADER, MAX_FRAGMENTED = 8, 65536  -- wire: kFragmentHeaderSize, kMaxFragmentedValue
local DEST_ALL = 0xFFFF  -- wire: kDestAll
-- the preferences' defaults: those of <network> (src/config/config.h)
local UDP_PORT, ETHERTYPE = 47800, 0x88B5  -- wire: udp_port, ethertype

-- Builds with Lua 5.2 have bit32; with 5.3 or later, the operators instead (a syntax
-- error for 5.2's parser, hence load()).
local band = bit32 and bit32.band or load("return function(a, b) return a & b end")()

-- code -> name, element size (docs/protocol.md "Types")
local TYPES = {
  [1] = { name = "bool", size = 1 },
  [2] = { name = "int32", size = 4 },
  [3] = { name = "uint32", size = 4 },
  [4] = { name = "int64", size = 8 },
  [5] = { name = "float", size = 4 },
  [6] = { name = "double", size = 8 },
}
local TYPE_NAMES = {}
for code, t in pairs(TYPES) do TYPE_NAMES[code] = t.name end

local f = {
  magic = ProtoField.uint32("ccomm.magic", "magic", base.HEX),
  version = ProtoField.uint8("ccomm.version", "version", base.DEC),
  flags = ProtoField.uint8("ccomm.flags", "flags", base.HEX),
  flag_heartbeat = ProtoField.bool("ccomm.flags.heartbeat", "heartbeat", 8, nil, F_HEARTBEAT),
  flag_auth = ProtoField.bool("ccomm.flags.auth", "authentication tag present", 8, nil, F_AUTH),
  flag_summary = ProtoField.bool("ccomm.flags.summary", "node summary", 8, nil, F_SUMMARY),
  flag_unknown = ProtoField.uint8("ccomm.flags.unknown", "unknown bits (must be 0)", base.HEX, nil, 0xFF - F_KNOWN),
  sender = ProtoField.uint16("ccomm.sender", "sender", base.DEC),
  config_hash = ProtoField.uint32("ccomm.config_hash", "config_hash", base.HEX),
  seq = ProtoField.uint32("ccomm.seq", "seq", base.DEC),
  send_time_ns = ProtoField.uint64("ccomm.send_time_ns", "send_time_ns", base.DEC),
  entry_count = ProtoField.uint16("ccomm.entry_count", "entry_count", base.DEC),
  payload_len = ProtoField.uint16("ccomm.payload_len", "payload_len", base.DEC),
  dest = ProtoField.uint16("ccomm.dest", "dest", base.DEC),
  reserved = ProtoField.uint16("ccomm.reserved", "reserved", base.HEX),
  entry = ProtoField.none("ccomm.entry", "entry"),
  e_signal = ProtoField.uint16("ccomm.entry.signal", "signal", base.DEC),
  e_type = ProtoField.uint8("ccomm.entry.type", "type", base.DEC, TYPE_NAMES),
  e_flags = ProtoField.uint8("ccomm.entry.flags", "flags", base.HEX),
  e_flag_event = ProtoField.bool("ccomm.entry.flags.event", "event (queued; clear: state)", 8, nil, E_EVENT),
  e_flag_fragment = ProtoField.bool("ccomm.entry.flags.fragment", "fragment (part of a large value)", 8, nil,
                                   E_FRAGMENT),
  e_flag_unknown = ProtoField.uint8("ccomm.entry.flags.unknown", "unknown bits (must be 0)", base.HEX, nil,
                                  0xFF - E_KNOWN),
  e_total_len = ProtoField.uint32("ccomm.entry.total_len", "total_len (whole value)", base.DEC),
  e_offset = ProtoField.uint32("ccomm.entry.offset", "offset (of this part)", base.DEC),
  e_count = ProtoField.uint16("ccomm.entry.count", "count", base.DEC),
  e_value_len = ProtoField.uint16("ccomm.entry.value_len", "value_len", base.DEC),
  e_seq = ProtoField.uint32("ccomm.entry.seq", "seq", base.DEC),
  e_reserved = ProtoField.uint32("ccomm.entry.reserved", "reserved", base.HEX),
  e_source_time_ns = ProtoField.uint64("ccomm.entry.source_time_ns", "source_time_ns", base.DEC),
  e_value = ProtoField.string("ccomm.entry.value", "value"),
  e_value_bytes = ProtoField.bytes("ccomm.entry.value_bytes", "value bytes (not decodable)"),
  e_padding = ProtoField.bytes("ccomm.entry.padding", "padding"),
  v_bool = ProtoField.bool("ccomm.entry.value.bool", "bool", base.NONE),
  v_int32 = ProtoField.int32("ccomm.entry.value.int32", "int32", base.DEC),
  v_uint32 = ProtoField.uint32("ccomm.entry.value.uint32", "uint32", base.DEC),
  v_int64 = ProtoField.int64("ccomm.entry.value.int64", "int64", base.DEC),
  v_float = ProtoField.float("ccomm.entry.value.float", "float"),
  v_double = ProtoField.double("ccomm.entry.value.double", "double"),
  unused = ProtoField.bytes("ccomm.unused", "payload bytes after the last entry"),
  auth_tag = ProtoField.bytes("ccomm.auth_tag", "authentication tag (keyed BLAKE2b-128, not verified here)"),
  trailing = ProtoField.bytes("ccomm.trailing", "trailing bytes"),
  decode_error = ProtoField.string("ccomm.decode_error", "decode error (first failure, as ccommd counts it)"),
  sender_name = ProtoField.string("ccomm.sender_name", "sender node"),
  dest_name = ProtoField.string("ccomm.dest_name", "destination node"),
  e_signal_name = ProtoField.string("ccomm.entry.signal_name", "signal name"),
  s_body = ProtoField.none("ccomm.summary", "node summary"),
  s_part = ProtoField.uint8("ccomm.summary.part", "part", base.DEC),
  s_parts = ProtoField.uint8("ccomm.summary.parts", "parts", base.DEC),
  s_record_count = ProtoField.uint16("ccomm.summary.record_count", "record_count", base.DEC),
  s_cycle_ms = ProtoField.uint32("ccomm.summary.cycle_ms", "cycle_ms", base.DEC),
  s_uptime_ns = ProtoField.uint64("ccomm.summary.uptime_ns", "uptime_ns", base.DEC),
  s_peers_alive = ProtoField.uint64("ccomm.summary.peers_alive", "peers_alive", base.HEX),
  s_frames_rx = ProtoField.uint64("ccomm.summary.frames_rx", "frames_rx", base.DEC),
  s_frames_tx = ProtoField.uint64("ccomm.summary.frames_tx", "frames_tx", base.DEC),
  s_frames_bad = ProtoField.uint64("ccomm.summary.frames_bad", "frames_bad", base.DEC),
  s_frames_lost = ProtoField.uint64("ccomm.summary.frames_lost", "frames_lost", base.DEC),
  s_socket_drops = ProtoField.uint64("ccomm.summary.socket_drops", "socket_drops", base.DEC),
  s_clock_state = ProtoField.uint8("ccomm.summary.clock_state", "clock_state", base.DEC,
    { [0] = "none", [1] = "syncing", [2] = "synced", [3] = "lost" }),
  s_clock_reserved = ProtoField.uint24("ccomm.summary.clock_reserved", "reserved", base.HEX),
  s_clock_error_ns = ProtoField.uint32("ccomm.summary.clock_error_ns", "clock_error_ns", base.DEC),
  s_clock_offset_ns = ProtoField.int64("ccomm.summary.clock_offset_ns", "clock_offset_ns (realtime - monotonic)", base.DEC),
  r_record = ProtoField.none("ccomm.summary.record", "record"),
  r_signal = ProtoField.uint16("ccomm.summary.record.signal", "signal", base.DEC),
  r_role = ProtoField.uint8("ccomm.summary.record.role", "role", base.DEC, { [1] = "producer", [2] = "consumer" }),
  r_flags = ProtoField.uint8("ccomm.summary.record.flags", "flags", base.HEX),
  r_flag_stale = ProtoField.bool("ccomm.summary.record.flags.stale", "stale", 8, nil, R_STALE),
  r_flag_never = ProtoField.bool("ccomm.summary.record.flags.never", "never (no value yet)", 8, nil, R_NEVER),
  r_rate_mhz = ProtoField.uint32("ccomm.summary.record.rate_mhz", "rate_mhz (values/s x 1000)", base.DEC),
  r_lost = ProtoField.uint64("ccomm.summary.record.lost", "lost", base.DEC),
  r_age_ms = ProtoField.uint32("ccomm.summary.record.age_ms", "age_ms", base.DEC),
  r_reserved = ProtoField.uint32("ccomm.summary.record.reserved", "reserved", base.HEX),
}
local field_list = {}
for _, field in pairs(f) do field_list[#field_list + 1] = field end
ccomm.fields = field_list

-- One expert info per DecodeError of docs/protocol.md "Validation", plus the receiver's
-- bad_signal (rule 6, only with a configuration loaded) and notes.
local E = {}
for _, name in ipairs({ "too_short", "bad_magic", "bad_version", "bad_header", "bad_entry", "trailing_bytes",
                        "bad_summary" }) do
  E[name] = ProtoExpert.new("ccomm." .. name, name, expert.group.MALFORMED, expert.severity.ERROR)
end
E.bad_signal = ProtoExpert.new("ccomm.bad_signal", "bad_signal", expert.group.PROTOCOL, expert.severity.WARN)
E.config_mismatch = ProtoExpert.new("ccomm.config_mismatch", "config_mismatch", expert.group.PROTOCOL,
                                    expert.severity.WARN)
E.config_error = ProtoExpert.new("ccomm.config_error", "signals.xml not loaded", expert.group.PROTOCOL,
                                 expert.severity.WARN)
E.note = ProtoExpert.new("ccomm.note", "note", expert.group.COMMENTS_GROUP, expert.severity.NOTE)
ccomm.experts = { E.too_short, E.bad_magic, E.bad_version, E.bad_header, E.bad_entry,
                  E.trailing_bytes, E.bad_summary, E.bad_signal, E.config_mismatch, E.config_error, E.note }

ccomm.prefs.udp_port = Pref.uint("UDP port", UDP_PORT, "UDP port of ccomm frames (<network udp_port=...>)")
ccomm.prefs.ethertype = Pref.uint("EtherType", ETHERTYPE, "EtherType of raw ccomm frames (<network ethertype=...>)")
ccomm.prefs.config = Pref.string("Configuration (JSON)", "",
  "Output of ccommd --check signals.xml --json: names nodes and signals, checks entries against it")

local udp_port_field = Field.new("udp.port")


-- ---- optional configuration ----------------------------------------------------------
-- The system's configuration as ccommd resolves it: the JSON that
-- `ccommd --check signals.xml --json` prints (ccommd's parser is the one reader of
-- signals.xml; its hash is what frames carry as config_hash). Nodes and signals come with
-- their ids. Only that output is read, so a few patterns do (names are identifiers, and
-- signal objects hold no nested object).
local config = { path = "", nodes = {}, node_ids = {}, signals = {}, hash = nil, error = nil }

local function load_config(path)
  config = { path = path, nodes = {}, node_ids = {}, signals = {}, hash = nil, error = nil }
  if path == "" then return end
  local fh, err = io.open(path, "r")
  if not fh then config.error = "cannot read the configuration: " .. tostring(err); return end
  local text = fh:read("*a")
  fh:close()
  local hash = text:match('"hash":"(%x+)"')
  local nodes = text:match('"nodes":%[(.-)%]')
  local signals = text:match('"signals":%[(.*)%],"sections"')
  if not (text:match('^{"format":1,') and hash and nodes and signals) then
    config.error = path .. " is not the output of ccommd --check signals.xml --json"
    return
  end
  for obj in nodes:gmatch("{(.-)}") do
    local id, name = tonumber(obj:match('"id":(%d+)')), obj:match('"name":"([^"]*)"')
    if id and name then config.nodes[id], config.node_ids[name] = name, id end
  end
  for obj in signals:gmatch("{(.-)}") do
    local id = tonumber(obj:match('"id":(%d+)'))
    local sig = { name = obj:match('"name":"([^"]*)"') or "?", type_name = obj:match('"type":"([^"]*)"') or "?",
                  count = tonumber(obj:match('"count":(%d+)') or "1") or 1,
                  kind = obj:match('"kind":"(%a+)"') or "state", producer = obj:match('"producer":"([^"]*)"') or "?" }
    for code, t in pairs(TYPES) do if t.name == sig.type_name then sig.type = code end end
    if id then config.signals[id] = sig end
  end
  config.hash = tonumber(hash, 16)
end

-- ---- value formatting ------------------------------------------------------------------
-- Shortest text that reads back as the same value (like Python's repr).
local function format_double(v)
  if v ~= v then return "nan" end
  if v == math.huge then return "inf" elseif v == -math.huge then return "-inf" end
  for digits = 1, 17 do
    local s = string.format("%." .. digits .. "g", v)
    if tonumber(s) == v then return s end
  end
  return string.format("%.17g", v)
end

local function format_float(v, raw)
  if v ~= v or v == math.huge or v == -math.huge then return format_double(v) end
  for digits = 1, 9 do
    local s = string.format("%." .. digits .. "g", v)
    if Struct.pack(">f", tonumber(s)) == raw then return s end
  end
  return string.format("%.9g", v)
end

local function format_ns(u64)  -- "1000000000" -> "1.000000000 s"
  local s = tostring(u64)
  if #s < 10 then s = string.rep("0", 10 - #s) .. s end
  return s:sub(1, -10) .. "." .. s:sub(-9) .. " s"
end

local function node_label(id)
  if id == DEST_ALL then return "all" end
  local name = config.nodes[id]
  return name and string.format("%d (%s)", id, name) or tostring(id)
end

-- ---- dissection ------------------------------------------------------------------------
-- Context of one frame: the tree, the first failure (what DecodeHeader would return).
local function problem(ctx, item, kind, text)
  item:add_proto_expert_info(E[kind], kind .. ": " .. text)
  if not ctx.first then ctx.first, ctx.first_text = kind, text end
end

local function all_zero(tvb, off, len)
  for i = off, off + len - 1 do
    if tvb(i, 1):uint() ~= 0 then return false end
  end
  return true
end

-- Adds a well-formed value: ccomm.entry.value (all elements as text), under it one typed
-- item per element (ccomm.entry.value.double ...) for filters; a fragment's elements are
-- numbered from `first`, their index in the whole value. Returns the text.
local function add_value(tree, tvb, off, code, count, fail, first)
  local t = TYPES[code]
  local texts = {}
  for i = 0, count - 1 do
    local r = tvb(off + i * t.size, t.size)
    if code == 1 then texts[i + 1] = (r:uint() == 1) and "true" or (r:uint() == 0 and "false" or tostring(r:uint()))
    elseif code == 2 then texts[i + 1] = tostring(r:int())
    elseif code == 3 then texts[i + 1] = tostring(r:uint())
    elseif code == 4 then texts[i + 1] = tostring(r:int64())
    elseif code == 5 then texts[i + 1] = format_float(r:float(), r:raw())
    else texts[i + 1] = format_double(r:float()) end
  end
  local text = table.concat(texts, ", ")
  local value_item = tree:add(f.e_value, tvb(off, count * t.size), text)
  for i = 0, count - 1 do
    local r = tvb(off + i * t.size, t.size)
    local item = value_item:add(f["v_" .. t.name], r)
    item:set_text(string.format("%s%s: %s", t.name, (count > 1 or first) and "[" .. (first or 0) + i .. "]" or "",
                                texts[i + 1]))
    if code == 1 and r:uint() > 1 then fail(item, "a bool byte other than 0 or 1 (" .. r:uint() .. ")") end
  end
  return text
end

-- One entry at `off` with `left` declared payload bytes; returns its size, or nil when
-- the rest of the payload cannot be walked.
local function dissect_entry(ctx, tvb, off, left, index, sender)
  local tree = ctx.root
  if left < ENTRY_HEADER then
    problem(ctx, tree, "bad_entry", string.format("entry %d: less than 24 bytes of payload left (%d)", index, left))
    return nil
  end
  -- the frame may be shorter than it declares (too_short), or cut by the capture's snap length
  local function missing(upto) return upto > ctx.flen and "beyond the received frame" or "not captured" end
  if off + ENTRY_HEADER > math.min(ctx.flen, tvb:len()) then
    tree:add_proto_expert_info(E.note, string.format("entry %d: %s", index, missing(off + ENTRY_HEADER)))
    return nil
  end
  local function bad(item, text) problem(ctx, item, "bad_entry", string.format("entry %d: %s", index, text)) end
  local signal, code, eflags = tvb(off, 2):uint(), tvb(off + 2, 1):uint(), tvb(off + 3, 1):uint()
  local count, value_len = tvb(off + 4, 2):uint(), tvb(off + 6, 2):uint()
  local padded = value_len + (-value_len % 8)
  local frag = band(eflags, E_FRAGMENT) ~= 0
  local head = ENTRY_HEADER + (frag and FRAGMENT_HEADER or 0)
  local size = head + padded
  local sub = tree:add(f.entry, tvb(off, math.min(size, left, tvb:len() - off)))
  local sig = config.signals[signal]
  local t = TYPES[code]
  sub:set_text(string.format("entry %d: signal %d%s, %s%s, %s%s, seq %d", index, signal,
    sig and " (" .. sig.name .. ")" or "", t and t.name or "type " .. code, count ~= 1 and "[" .. count .. "]" or "",
    band(eflags, E_EVENT) ~= 0 and "event" or "state", frag and " fragment" or "", tvb(off + 8, 4):uint()))
  sub:add(f.e_signal, tvb(off, 2))
  if sig then sub:add(f.e_signal_name, tvb(off, 2), sig.name):set_generated() end
  local type_item = sub:add(f.e_type, tvb(off + 2, 1))
  local flags_item = sub:add(f.e_flags, tvb(off + 3, 1))
  flags_item:add(f.e_flag_event, tvb(off + 3, 1))
  flags_item:add(f.e_flag_fragment, tvb(off + 3, 1))
  flags_item:add(f.e_flag_unknown, tvb(off + 3, 1))
  local count_item = sub:add(f.e_count, tvb(off + 4, 2))
  local len_item = sub:add(f.e_value_len, tvb(off + 6, 2))
  sub:add(f.e_seq, tvb(off + 8, 4))
  local res_item = sub:add(f.e_reserved, tvb(off + 12, 4))
  local time_item = sub:add(f.e_source_time_ns, tvb(off + 16, 8))
  time_item:append_text(" (" .. format_ns(tvb(off + 16, 8):uint64()) .. ")")

  -- the checks of CheckEntry(), in its order
  local ok = true
  local function fail(item, text) ok = false; bad(item, text) end
  if not t then fail(type_item, "unknown type " .. code) end
  if band(eflags, 0xFF - E_KNOWN) ~= 0 then
    fail(flags_item, string.format("unknown entry flag bits 0x%02x", band(eflags, 0xFF - E_KNOWN)))
  end
  if count == 0 then fail(count_item, "count 0") end
  if tvb(off + 12, 4):uint() ~= 0 then fail(res_item, string.format("reserved not 0 (0x%08x)", tvb(off + 12, 4):uint())) end
  if frag and left < head then
    fail(sub, string.format("less than 32 bytes of payload left (%d)", left))
    return nil
  elseif frag and off + head <= tvb:len() then
    local total, offset = tvb(off + 24, 4):uint(), tvb(off + 28, 4):uint()
    local total_item = sub:add(f.e_total_len, tvb(off + 24, 4))
    local offset_item = sub:add(f.e_offset, tvb(off + 28, 4))
    sub:append_text(string.format(", bytes %d-%d of %d", offset, offset + value_len, total))
    if t and (total ~= count * t.size or total > MAX_FRAGMENTED) then
      fail(total_item, string.format("fragment total_len not count x element size, or above 65536 (%d)", total))
    elseif t and (value_len == 0 or value_len % t.size ~= 0 or value_len >= total) then
      fail(len_item, string.format("fragment part of 0 bytes, not a multiple of the element size, or not smaller than total_len (%d)", value_len))
    elseif t and offset % t.size ~= 0 then
      fail(offset_item, string.format("fragment offset not a multiple of the element size (%d)", offset))
    elseif t and offset + value_len > total then
      fail(offset_item, string.format("fragment part running past total_len (%d + %d > %d)", offset, value_len, total))
    end
  elseif t and count > 0 and value_len ~= count * t.size then
    fail(len_item, string.format("value_len %d not count x element size (%d x %d = %d)", value_len, count, t.size, count * t.size))
  end
  if size > left then
    fail(sub, string.format("value and padding running past the payload (entry needs %d bytes, %d left)", size, left))
    return nil
  end
  local voff = off + head
  if voff + padded > math.min(ctx.flen, tvb:len()) then
    sub:add_proto_expert_info(E.note, "value " .. missing(voff + padded))
    return size
  end
  if ok then
    local first = frag and math.floor(tvb(off + 28, 4):uint() / t.size) or nil
    sub:append_text(": " .. add_value(sub, tvb, voff, code, first and math.floor(value_len / t.size) or count, fail, first))
  elseif value_len > 0 then
    sub:add(f.e_value_bytes, tvb(voff, value_len))
  end
  if padded > value_len then
    local pad_item = sub:add(f.e_padding, tvb(voff + value_len, padded - value_len))
    if not all_zero(tvb, voff + value_len, padded - value_len) then fail(pad_item, "a non-zero padding byte") end
  end

  -- receiver rule 6 against the loaded configuration (the frame itself is well-formed)
  if ok and config.hash and ctx.hash_ok then
    local want = sig
    local why
    if not want then why = "no signal " .. signal .. " in signals.xml"
    elseif config.node_ids[want.producer] ~= sender then why = "produced by " .. want.producer .. ", not by the sender"
    elseif want.type ~= code then why = "signals.xml says type " .. want.type_name
    elseif want.count ~= count then why = "signals.xml says count " .. want.count
    elseif (want.kind == "event") ~= (band(eflags, E_EVENT) ~= 0) then why = "signals.xml says kind " .. want.kind end
    if why then sub:add_proto_expert_info(E.bad_signal, "bad_signal: " .. why) end
  end
  return size
end

-- A node summary's body (SummaryBodyValid): head, then records, within what was captured.
local S_HEAD_FIELDS = { { "s_part", 0, 1 }, { "s_parts", 1, 1 }, { "s_record_count", 2, 2 }, { "s_cycle_ms", 4, 4 },
  { "s_uptime_ns", 8, 8 }, { "s_peers_alive", 16, 8 }, { "s_frames_rx", 24, 8 }, { "s_frames_tx", 32, 8 },
  { "s_frames_bad", 40, 8 }, { "s_frames_lost", 48, 8 }, { "s_socket_drops", 56, 8 }, { "s_clock_state", 64, 1 },
  { "s_clock_reserved", 65, 3 }, { "s_clock_error_ns", 68, 4 }, { "s_clock_offset_ns", 72, 8 } }
local function dissect_summary(ctx, tvb, len, avail)
  local function bad(item, text) problem(ctx, item, "bad_summary", text) end
  local body = ctx.root:add(f.s_body, tvb(HEADER, math.max(0, math.min(len, avail - HEADER))))
  if len < S_HEAD then return bad(body, string.format("body shorter than its 80-byte head (%d bytes)", len)) end
  if avail < HEADER + S_HEAD then return end  -- not all there: too_short already says so
  for _, x in ipairs(S_HEAD_FIELDS) do body:add(f[x[1]], tvb(HEADER + x[2], x[3])) end
  local part, parts, n = tvb(HEADER, 1):uint(), tvb(HEADER + 1, 1):uint(), tvb(HEADER + 2, 2):uint()
  ctx.summary_text = string.format(", part %d/%d, %d record%s", part, parts, n, n == 1 and "" or "s")
  if parts == 0 or part >= parts then bad(body, string.format("part not below parts (%d, %d)", part, parts)) end
  if n > S_MAX then bad(body, string.format("record_count above 56 (%d)", n)) end
  local clock_state = tvb(HEADER + 64, 1):uint()
  if clock_state >= CLOCK_STATES then bad(body, string.format("unknown clock_state (%d)", clock_state)) end
  if tvb(HEADER + 65, 3):uint() ~= 0 then bad(body, "clock reserved bytes not 0") end
  if len ~= S_HEAD + n * S_RECORD then bad(body, string.format("payload_len not 80 + 24 x record_count (%d)", len)) end
  local last, off = -1, HEADER + S_HEAD
  for i = 0, n - 1 do
    if off + S_RECORD > HEADER + len or off + S_RECORD > avail then break end
    local sig, role, rflags = tvb(off, 2):uint(), tvb(off + 2, 1):uint(), tvb(off + 3, 1):uint()
    local rec = body:add(f.r_record, tvb(off, S_RECORD))
    rec:append_text(string.format(" %d: signal %s, %s", i, sig, role == 1 and "producer" or role == 2 and "consumer" or "?"))
    rec:add(f.r_signal, tvb(off, 2))
    if config.signals[sig] then rec:add(f.e_signal_name, tvb(off, 2), config.signals[sig].name):set_generated() end
    local role_item = rec:add(f.r_role, tvb(off + 2, 1))
    local flags_item = rec:add(f.r_flags, tvb(off + 3, 1))
    flags_item:add(f.r_flag_stale, tvb(off + 3, 1))
    flags_item:add(f.r_flag_never, tvb(off + 3, 1))
    rec:add(f.r_rate_mhz, tvb(off + 4, 4))
    rec:add(f.r_lost, tvb(off + 8, 8))
    local age_item = rec:add(f.r_age_ms, tvb(off + 16, 4))
    if tvb(off + 16, 4):uint() == NO_AGE then age_item:append_text(" (none)") end
    local res_item = rec:add(f.r_reserved, tvb(off + 20, 4))
    if sig <= last then bad(rec, string.format("record %d: signals not strictly increasing (%d after %d)", i, sig, last)) end
    if role ~= 1 and role ~= 2 then bad(role_item, string.format("record %d: unknown role (%d)", i, role)) end
    if band(rflags, 0xFF - R_KNOWN) ~= 0 then
      bad(flags_item, string.format("record %d: unknown record flag bits (0x%02x)", i, rflags))
    end
    if tvb(off + 20, 4):uint() ~= 0 then bad(res_item, string.format("record %d: reserved not 0", i)) end
    last, off = sig, off + S_RECORD
  end
end

local function dissect(tvb, pinfo, tree)
  local clen = tvb:len()               -- captured bytes
  local rlen = tvb:reported_length_remaining()  -- bytes on the wire (a snap length may cut)
  if rlen <= 0 then return 0 end
  local over_udp = udp_port_field() ~= nil
  pinfo.cols.protocol:set("CCOMM")

  -- Raw Ethernet pads payloads under 46 bytes with zeros: drop them as
  -- TrimEthernetPadding() does (protocol.md "Transport encapsulation"). UDP has none.
  local flen = rlen
  if not over_udp and rlen >= HEADER and rlen <= ETH_MIN_PAYLOAD and clen == rlen then
    local declared = HEADER + tvb(26, 2):uint() + (band(tvb(5, 1):uint(), F_AUTH) ~= 0 and TAG_SIZE or 0)
    if declared < rlen and all_zero(tvb, declared, rlen - declared) then flen = declared end
  end

  local root = tree:add(ccomm, tvb(0, math.min(flen, clen)))
  local ctx = { root = root, flen = flen }
  local function add(field, off, size)
    if off + size <= clen then return root:add(field, tvb(off, size)) end
  end
  local function finish(summary)
    if config.error then root:add_proto_expert_info(E.config_error, config.error) end
    if flen < rlen then
      root:add_proto_expert_info(E.note, string.format("%d zero byte(s) after the frame: Ethernet padding, dropped as a raw receiver does", rlen - flen))
    end
    if ctx.first then
      root:add(f.decode_error, ctx.first):set_generated()
      summary = summary .. " [" .. ctx.first .. ": " .. ctx.first_text .. "]"
    end
    root:append_text(", " .. summary)
    pinfo.cols.info:set(summary)
    return flen
  end

  -- 1. fewer than 32 bytes (or fewer captured: then nothing can be checked)
  if flen < HEADER or clen < HEADER then
    local magic_item = add(f.magic, 0, 4)
    add(f.version, 4, 1)
    add(f.flags, 5, 1)
    add(f.sender, 6, 2)
    add(f.config_hash, 8, 4)
    add(f.seq, 12, 4)
    add(f.send_time_ns, 16, 8)
    add(f.entry_count, 24, 2)
    add(f.payload_len, 26, 2)
    add(f.dest, 28, 2)
    if flen < HEADER then
      problem(ctx, magic_item or root, "too_short", string.format("fewer than 32 bytes (%d)", flen))
    else
      root:add_proto_expert_info(E.note, string.format("header not captured (%d of 32 bytes)", clen))
    end
    return finish(string.format("%d bytes", flen))
  end

  local magic, version, flags = tvb(0, 4):uint(), tvb(4, 1):uint(), tvb(5, 1):uint()
  local sender, seq = tvb(6, 2):uint(), tvb(12, 4):uint()
  local entry_count, payload_len = tvb(24, 2):uint(), tvb(26, 2):uint()
  local dest, reserved = tvb(28, 2):uint(), tvb(30, 2):uint()
  local heartbeat = band(flags, F_HEARTBEAT) ~= 0
  local auth = band(flags, F_AUTH) ~= 0
  local is_summary = band(flags, F_SUMMARY) ~= 0

  local magic_item = root:add(f.magic, tvb(0, 4))
  local version_item = root:add(f.version, tvb(4, 1))
  local flags_item = root:add(f.flags, tvb(5, 1))
  flags_item:add(f.flag_heartbeat, tvb(5, 1))
  flags_item:add(f.flag_auth, tvb(5, 1))
  flags_item:add(f.flag_summary, tvb(5, 1))
  flags_item:add(f.flag_unknown, tvb(5, 1))
  local sender_item = root:add(f.sender, tvb(6, 2))
  if config.nodes[sender] then root:add(f.sender_name, tvb(6, 2), config.nodes[sender]):set_generated() end
  local hash_item = root:add(f.config_hash, tvb(8, 4))
  root:add(f.seq, tvb(12, 4))
  root:add(f.send_time_ns, tvb(16, 8)):append_text(" (" .. format_ns(tvb(16, 8):uint64()) .. ")")
  local count_item = root:add(f.entry_count, tvb(24, 2))
  local plen_item = root:add(f.payload_len, tvb(26, 2))
  local dest_item = root:add(f.dest, tvb(28, 2))
  if dest == DEST_ALL then dest_item:append_text(" (all nodes)") end
  if config.nodes[dest] then root:add(f.dest_name, tvb(28, 2), config.nodes[dest]):set_generated() end
  local res_item = root:add(f.reserved, tvb(30, 2))
  local summary = string.format("%s %s -> %s, seq %d", is_summary and "summary" or heartbeat and "heartbeat" or "data",
                                node_label(sender), node_label(dest), seq)
  if not heartbeat and not is_summary then summary = summary .. string.format(", %d entr%s", entry_count, entry_count == 1 and "y" or "ies") end

  -- 2. magic and version: without them the layout of the rest is unknown
  if magic ~= MAGIC then
    problem(ctx, magic_item, "bad_magic", string.format("wrong magic 0x%08x (expected 0x43434d57, \"CCMW\")", magic))
    return finish(summary)
  end
  if version ~= VERSION then
    problem(ctx, version_item, "bad_version", string.format("wrong version %d (this dissector knows version 2)", version))
    return finish(summary)
  end

  -- 3. the header's own rules
  if band(flags, 0xFF - F_KNOWN) ~= 0 then
    problem(ctx, flags_item, "bad_header", string.format("unknown flag bits 0x%02x", band(flags, 0xFF - F_KNOWN)))
  end
  if reserved ~= 0 then problem(ctx, res_item, "bad_header", string.format("reserved not 0 (0x%04x)", reserved)) end
  if is_summary then
    if heartbeat or entry_count ~= 0 or payload_len == 0 then
      problem(ctx, count_item, "bad_header", "a summary that is also a heartbeat or has entries or no payload")
    end
  elseif heartbeat and (entry_count ~= 0 or payload_len ~= 0) then
    problem(ctx, count_item, "bad_header", "a heartbeat with entries or payload")
  elseif not heartbeat and (entry_count == 0 or payload_len == 0) then
    problem(ctx, count_item, "bad_header", "a data frame without entries or payload")
  end
  if payload_len % 8 ~= 0 then
    problem(ctx, plen_item, "bad_header", string.format("payload_len %d not a multiple of 8", payload_len))
  end
  local total = HEADER + payload_len + (auth and TAG_SIZE or 0)
  if total > MAX_FRAME then
    problem(ctx, plen_item, "bad_header", string.format("declared total %d above 1472", total))
  else
    -- 4. received length against the declared one
    if flen < total then
      problem(ctx, plen_item, "too_short", string.format("received length %d below the declared total %d", flen, total))
    elseif flen > total then
      local item = total < clen and root:add(f.trailing, tvb(total, math.min(flen, clen) - total)) or root
      problem(ctx, item, "trailing_bytes", string.format("received length %d above the declared total %d", flen, total))
    end
  end

  -- configuration (receiver rule 4), only when a signals.xml is loaded
  ctx.hash_ok = config.hash ~= nil and tvb(8, 4):uint() == config.hash
  if config.hash and not ctx.hash_ok then
    hash_item:add_proto_expert_info(E.config_mismatch, string.format(
      "config_mismatch: the loaded signals.xml hashes to %08x", config.hash))
  end

  -- 5. the entries, within the declared payload (and what was captured)
  -- (a frame cut short shows its entries up to the end of the captured bytes);
  -- 7. for a summary its body instead
  local off, left, walked = HEADER, payload_len, not is_summary
  if is_summary then
    dissect_summary(ctx, tvb, payload_len, math.min(flen, clen))
    summary = summary .. (ctx.summary_text or "")
  end
  for i = 0, (is_summary and -1 or entry_count - 1) do
    local size = dissect_entry(ctx, tvb, off, left, i, sender)
    if not size then walked = false; break end
    off, left = off + size, left - size
  end
  -- 6. payload left over after entry_count entries
  if walked and left > 0 then
    local item = off < clen and root:add(f.unused, tvb(off, math.min(left, clen - off))) or root
    problem(ctx, item, "bad_header", string.format("payload bytes left after entry_count entries (%d)", left))
  end

  if auth and HEADER + payload_len + TAG_SIZE <= math.min(flen, clen) then
    root:add(f.auth_tag, tvb(HEADER + payload_len, TAG_SIZE))
  end
  return finish(summary)
end

function ccomm.dissector(tvb, pinfo, tree)
  return dissect(tvb, pinfo, tree)
end

-- UDP on another port than the preference: frames that start with magic and VERSION.
local function heuristic(tvb, pinfo, tree)
  if tvb:len() < 8 or tvb(0, 4):uint() ~= MAGIC or tvb(4, 1):uint() ~= VERSION then return false end
  dissect(tvb, pinfo, tree)
  return true
end

local registered = { udp_port = nil, ethertype = nil }
local function register()
  local udp, eth = DissectorTable.get("udp.port"), DissectorTable.get("ethertype")
  if registered.udp_port then udp:remove(registered.udp_port, ccomm) end
  if registered.ethertype then eth:remove(registered.ethertype, ccomm) end
  registered.udp_port, registered.ethertype = ccomm.prefs.udp_port, ccomm.prefs.ethertype
  udp:add(registered.udp_port, ccomm)
  eth:add(registered.ethertype, ccomm)
end

function ccomm.prefs_changed()
  register()
  if ccomm.prefs.config ~= config.path then load_config(ccomm.prefs.config) end
end

register()
ccomm:register_heuristic("udp", heuristic)
