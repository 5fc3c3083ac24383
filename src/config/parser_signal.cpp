// SPDX-License-Identifier: Apache-2.0
// <signal> elements and their safe values.
#include <cstring>
#include <charconv>
#include <limits>
#include <system_error>

#include "config/parser.h"

namespace ccomm {
namespace config_detail {

void Parser::SignalElement(const Node* n, SignalConfig* sig, SignalRefs* refs) {
  Element e(n, {"name", "type", "count", "kind", "producer", "consumers", "stale_after_ms",
                "stale_by", "safe_value", "period_ms", "rate_hz", "queue_depth"},
            &diag_);
  sig->line = e.line();
  Name(e, "signal", &sig->name);
  CheckNoText(n, &diag_);
  for (const Node* c = n->first_node(); c; c = c->next_sibling())
    if (c->type() == rapidxml::node_element)
      Err(diag_.LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) +
                                       "> in <signal> (it has no child elements)");

  std::vector<std::string> type_names;
  for (ValueType t : kAllValueTypes) type_names.emplace_back(ValueTypeName(t));
  if (const AttrValue* a = e.Get("type")) {
    if (!ParseValueType(a->value, &sig->type)) {
      Err(a->line, "unknown type " + Quote(a->value) + " (expected " + Join(type_names, ", ") + ")");
      refs->ok = false;
    }
  } else {
    if (!e.Has("type"))
      Err(e.line(), "signal without type= (expected " + Join(type_names, ", ") + ")");
    refs->ok = false;
  }
  if (e.Has("count") && !Unsigned(e, "count", 1, kMaxArrayCount, &sig->count)) refs->ok = false;
  if (refs->ok && sig->value_bytes() > kMaxValueBytes) {
    const AttrValue* a = e.Get("count");
    Err(a ? a->line : e.line(),
        "signal value is " + std::to_string(sig->value_bytes()) + " bytes (count " +
            std::to_string(sig->count) + " x " + std::to_string(ValueTypeSize(sig->type)) +
            "-byte " + ValueTypeName(sig->type) + "); at most " + std::to_string(kMaxValueBytes) +
            " per signal");
    refs->ok = false;
  }
  bool kind_ok = true;
  if (const AttrValue* a = e.Get("kind")) {
    if (a->value == "state") {
      sig->kind = SignalKind::kState;
    } else if (a->value == "event") {
      sig->kind = SignalKind::kEvent;
    } else {
      Err(a->line, "unknown kind " + Quote(a->value) + " (expected state or event)");
      kind_ok = false;
    }
  }
  bool is_event = kind_ok && sig->kind == SignalKind::kEvent;
  bool is_state = kind_ok && sig->kind == SignalKind::kState;

  if (const AttrValue* a = e.Get("producer")) {
    refs->producer = a->value;
    refs->producer_line = a->line;
  } else if (!e.Has("producer")) {
    Err(e.line(), "signal without producer= (every signal has exactly one producer node)");
  }
  if (const AttrValue* a = e.Get("consumers")) {
    // Names separated by commas and/or blanks; "" = local-only.
    std::vector<std::string_view> names;
    if (!SplitList(a->value, &names))
      Err(a->line, "empty name in consumers " + Quote(a->value));
    else
      for (std::string_view name : names) refs->consumers.emplace_back(std::string(name), a->line);
  }

  uint64_t stale = 0;
  if (Unsigned(e, "stale_after_ms", 0, kMaxStaleAfterMs, &stale)) {
    if (is_event) {
      Err(e.Get("stale_after_ms")->line,
          "stale_after_ms applies only to state signals (events are queued, never stale)");
    } else {
      sig->stale_after_ms = static_cast<uint32_t>(stale);
    }
  }

  if (const AttrValue* a = e.Get("stale_by")) {
    if (a->value == "production") sig->stale_by = StaleBy::kProduction;
    else if (a->value != "arrival")
      Err(a->line, "unknown stale_by " + Quote(a->value) + " (expected arrival or production)");
    if (is_event)
      Err(a->line, "stale_by applies only to state signals (events are queued, never stale)");
  }

  const AttrValue* period = e.Get("period_ms");
  const AttrValue* rate = e.Get("rate_hz");
  if (period && rate) {
    Err(rate->line, "both period_ms and rate_hz given (use one)");
  } else if (period || rate) {
    const AttrValue* a = period ? period : rate;
    const char* attr = period ? "period_ms" : "rate_hz";
    uint64_t scaled = 0;
    NumResult r = ParseFixed(a->value, 3, &scaled);
    if (r == NumResult::kSyntax) {
      Err(a->line, "invalid " + std::string(attr) + " " + Quote(a->value) +
                       (period ? " (expected milliseconds like 10 or 0.5, resolution 0.001)"
                               : " (expected a frequency like 1000 or 0.5, resolution 0.001)"));
    } else if (r == NumResult::kRange || scaled == 0) {
      Err(a->line, std::string(attr) + " " + a->value + " out of range (expected " +
                       (period ? "0.05..60000)" : "0.017..20000)"));
    } else {
      // period_ms is in microseconds after scaling; rate_hz in millihertz.
      uint64_t us = period ? scaled : (1000000000ull + scaled / 2) / scaled;
      if (us < kMinPeriodUs || us > kMaxPeriodUs) {
        Err(a->line, std::string(attr) + " " + a->value + " gives a period of " +
                         std::to_string(us) + " us (expected 50 us .. 60 s: " +
                         (period ? "period_ms 0.05..60000)" : "rate_hz 0.017..20000)"));
      } else if (is_event) {
        Err(a->line, std::string(attr) +
                         " applies only to state signals (events are sent when written)");
      } else {
        sig->period_us = static_cast<uint32_t>(us);
      }
    }
  }
  if (sig->stale_after_ms != 0 && sig->period_us != 0 &&
      uint64_t{sig->stale_after_ms} * 1000 <= sig->period_us) {
    Err(e.Get("stale_after_ms")->line,
        "stale_after_ms " + std::to_string(sig->stale_after_ms) +
            " is not longer than the period (" + std::to_string(sig->period_us) +
            " us): the signal would go stale between updates");
  }

  if (e.Has("queue_depth")) {
    uint32_t depth = 0;
    if (Unsigned(e, "queue_depth", kMinQueueDepth, kMaxQueueDepth, &depth)) {
      int line = e.Get("queue_depth")->line;
      if (depth & (depth - 1))
        Err(line, "queue_depth " + std::to_string(depth) + " is not a power of two");
      else if (is_state)
        Err(line, "queue_depth applies only to event signals (a state holds one value)");
      else if (uint64_t{depth} * sig->value_bytes() > kMaxQueueBytes)
        Err(line, "queue_depth " + std::to_string(depth) + " x " + std::to_string(sig->value_bytes()) +
                      "-byte values is more than " + std::to_string(kMaxQueueBytes >> 20) +
                      " MiB of queue: at most " + std::to_string(kMaxQueueBytes / sig->value_bytes()) +
                      " values of this size");
      else
        sig->queue_depth = depth;
    }
  }

  if (const AttrValue* a = e.Get("safe_value")) {
    // Readers get the safe value before the first value arrives and while the signal
    // is stale (client.cpp); both exist only for state signals.
    if (is_event) {
      Err(a->line, "safe_value applies only to state signals (an event queue has no "
                   "current value to replace)");
    } else if (refs->ok) {
      SafeValue(*a, sig);
    }
  }
}

void Parser::SafeValue(const AttrValue& a, SignalConfig* sig) {
  std::vector<std::string_view> items;
  if (!SplitList(a.value, &items)) {
    Err(a.line, "empty element in safe_value " + Quote(a.value));
    return;
  }
  if (items.empty()) {
    Err(a.line, "empty safe_value");
    return;
  }
  if (items.size() != 1 && items.size() != sig->count) {
    Err(a.line, "safe_value has " + std::to_string(items.size()) + " values; signal has count " +
                    std::to_string(sig->count) + " (give 1 value for all elements or exactly " +
                    std::to_string(sig->count) + ")");
    return;
  }
  const size_t esize = ValueTypeSize(sig->type);
  std::vector<uint8_t> one(esize);
  std::vector<uint8_t> bytes;
  bytes.reserve(sig->value_bytes());
  const char* tname = ValueTypeName(sig->type);
  for (std::string_view item : items) {
    const NumResult r = ParseValueElement(sig->type, item, one.data());
    const std::string bad = r == NumResult::kSyntax ? "syntax" : r == NumResult::kRange ? "range" : "";
    if (bad == "syntax") {
      const char* expect = sig->type == ValueType::kBool ? "true, false, 1 or 0"
                           : sig->type == ValueType::kFloat || sig->type == ValueType::kDouble
                               ? "a number"
                               : "an integer";
      Err(a.line, "invalid safe_value " + Quote(item) + " for type " + tname + " (expected " +
                      expect + ")");
      return;
    }
    if (bad == "range") {
      Err(a.line, "safe_value " + std::string(item) + " out of range for type " + tname);
      return;
    }
    bytes.insert(bytes.end(), one.begin(), one.end());
  }
  if (items.size() == 1)
    for (uint32_t k = 1; k < sig->count; ++k) bytes.insert(bytes.end(), one.begin(), one.end());
  sig->safe_value = std::move(bytes);
  sig->has_safe_value = true;
}

}  // namespace config_detail
}  // namespace ccomm
