// SPDX-License-Identifier: Apache-2.0
// Extension sections of signals.xml (outline.h: kExtensionSections, e.g. <ros2>): the core
// checks their structure only and keeps them as element trees with line numbers; the
// program that owns a section checks its meaning. Local policy like <realtime>: not part
// of the configuration hash.
#include "config/parser.h"

namespace ccomm {
namespace config_detail {

bool IsExtensionSection(std::string_view name) {
  for (const ExtensionSection& s : kExtensionSections)
    if (name == s.name) return true;
  return false;
}

// Depth is bounded before parsing (kMaxXmlDepth), so the recursion is too.
void Parser::ExtensionElement(const Node* n, SectionElement* out) {
  out->name = std::string(NameOf(n));
  out->line = diag_.LineOf(n->name());
  CheckNoText(n, &diag_);
  for (const Attribute* a = n->first_attribute(); a; a = a->next_attribute()) {
    SectionAttribute attr;
    attr.name = std::string(NameOf(a));
    attr.line = diag_.LineOf(a->name());
    bool repeated = false;
    for (const SectionAttribute& seen : out->attributes)
      if (seen.name == attr.name) {
        Err(attr.line, "duplicate attribute " + Quote(attr.name) + " on <" + out->name +
                           "> (first at line " + std::to_string(seen.line) + ")");
        repeated = true;
        break;
      }
    if (repeated) continue;
    std::string bad;
    if (!DecodeEntities(std::string_view(a->value(), a->value_size()), &attr.value, &bad)) {
      if (bad == "<")
        Err(attr.line, "'<' in the value of " + attr.name + " (write &lt;)");
      else
        Err(attr.line, "invalid entity reference " + Quote(bad) + " in the value of " + attr.name);
      continue;
    }
    out->attributes.push_back(std::move(attr));
  }
  for (const Node* c = n->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    SectionElement child;
    ExtensionElement(c, &child);
    out->children.push_back(std::move(child));
  }
}

}  // namespace config_detail
}  // namespace ccomm
