// SPDX-License-Identifier: Apache-2.0
// The XML layer of the configuration parser: RapidXML without exceptions, a depth guard
// in front of it, and the names of the DOM types the element parsers walk.
#pragma once

#define RAPIDXML_NO_EXCEPTIONS
#include <rapidxml/rapidxml.hpp>

#include <csetjmp>
#include <cstddef>
#include <string_view>

namespace ccomm {
namespace config_detail {

using Node = rapidxml::xml_node<char>;
using Attribute = rapidxml::xml_attribute<char>;

inline std::string_view NameOf(const Node* n) { return std::string_view(n->name(), n->name_size()); }
inline std::string_view NameOf(const Attribute* a) { return std::string_view(a->name(), a->name_size()); }

/// Where and why RapidXML gave up (see xml_input.cpp for how it gets here).
struct XmlFailure {
  std::jmp_buf env;
  const char* what = nullptr;
  const char* where = nullptr;
};

/// Elements may nest at most this deep (RapidXML recurses once per level).
constexpr int kMaxXmlDepth = 32;
/// Offset of the first element nested deeper than kMaxXmlDepth, or npos.
size_t FindTooDeep(std::string_view text);
/// Parses NUL-terminated `text` (unchanged: parse_non_destructive) into `doc`; false with
/// `failure` filled on a syntax error.
bool RunXmlParse(rapidxml::xml_document<char>* doc, char* text, XmlFailure* failure);

}  // namespace config_detail
}  // namespace ccomm
