// SPDX-License-Identifier: Apache-2.0
// RapidXML behind a depth guard and without exceptions (see the comment below).
#include "config/xml_input.h"

#include <cstdlib>

// ---------------------------------------------------------------------------------------
// RapidXML error handling without exceptions.
//
// Core code is built with -fno-exceptions, so RapidXML calls this handler instead of
// throwing, and the handler must not return. We longjmp back to RunXmlParse(), which is
// safe because:
//  * C++ allows longjmp exactly when an equivalent throw/catch would run no non-trivial
//    destructors ([csetjmp.syn]). Every frame between RunXmlParse() and the handler is a
//    RapidXML parse function, whose automatic objects are all raw pointers and chars.
//  * RunXmlParse() modifies no local variable after setjmp(), so nothing is indeterminate
//    after the jump.
//  * Nodes already built live in the document's memory pool, which records every block
//    when it is allocated; ~xml_document() frees them as usual.
//  * The jump target is thread-local, so parses on different threads do not interfere.
//    A parse that is not running under RunXmlParse() (nobody else in ccomm uses RapidXML)
//    aborts instead of returning into RapidXML.
namespace {
thread_local ccomm::config_detail::XmlFailure* t_xml_failure = nullptr;
}  // namespace

namespace rapidxml {
void parse_error_handler(const char* what, void* where) {
  ccomm::config_detail::XmlFailure* f = t_xml_failure;
  if (f == nullptr) std::abort();
  f->what = what;
  f->where = static_cast<const char*>(where);
  std::longjmp(f->env, 1);
}
}  // namespace rapidxml

namespace ccomm {
namespace config_detail {

// Comment nodes are kept only to check them (CheckComments); the walk skips them.
constexpr int kXmlFlags = rapidxml::parse_non_destructive | rapidxml::parse_validate_closing_tags |
                          rapidxml::parse_comment_nodes;

// RapidXML recurses once per element level, so a file of a million nested elements would
// overflow the stack. The format nests three levels deep; refuse anything far deeper
// before RapidXML sees it. This scan counts at least the depth RapidXML would reach
// (comments, CDATA, <!...>, <?...?> and quoted attribute values are skipped as RapidXML
// skips them; anything it might misjudge only makes the count higher).

size_t FindTooDeep(std::string_view t) {
  int depth = 0;
  size_t i = 0;
  auto skip_past = [&t](size_t from, std::string_view end) {
    size_t e = t.find(end, from);
    return e == std::string_view::npos ? t.size() : e + end.size();
  };
  while ((i = t.find('<', i)) != std::string_view::npos) {
    std::string_view rest = t.substr(i);
    if (rest.substr(0, 4) == "<!--") {
      i = skip_past(i + 4, "-->");
    } else if (rest.substr(0, 9) == "<![CDATA[") {
      i = skip_past(i + 9, "]]>");
    } else if (rest.size() > 1 && (rest[1] == '!' || rest[1] == '?')) {
      i = skip_past(i + 2, ">");
    } else if (rest.size() > 1 && rest[1] == '/') {
      if (depth > 0) --depth;
      i += 2;
    } else {
      size_t j = i + 1;
      char quote = 0;
      for (; j < t.size(); ++j) {
        char c = t[j];
        if (quote) {
          if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
          quote = c;
        } else if (c == '>') {
          break;
        }
      }
      const bool self_closing = j < t.size() && t[j - 1] == '/';
      if (!self_closing && ++depth > kMaxXmlDepth) return i;
      i = j;
    }
  }
  return std::string_view::npos;
}

// Runs the parse with a longjmp target for parse_error_handler (see the top of the file
// for why this is safe). No local of this function changes after setjmp().
bool RunXmlParse(rapidxml::xml_document<char>* doc, char* text, XmlFailure* failure) {
  t_xml_failure = failure;
  if (setjmp(failure->env) != 0) {
    t_xml_failure = nullptr;
    return false;
  }
  doc->parse<kXmlFlags>(text);
  t_xml_failure = nullptr;
  return true;
}


}  // namespace config_detail
}  // namespace ccomm
