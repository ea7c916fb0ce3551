#pragma once
// Names of blocks and sets come from input files and go into every output (.msh's quoted
// $PhysicalNames, .vtu XML attributes, Exodus name records, the JSON report). One rule makes
// each of them safe, applied by every reader to what it reads and by every writer to what it
// writes, so that a name reads back the same from any format:
// - bytes that are not valid UTF-8 become U+FFFD (the replacement character);
// - control characters (U+0000 to U+001F, U+007F: newline, tab, NUL, escape) become a space;
// - the double quote '"' becomes the apostrophe '\'' (.msh quotes names and has no escape);
// - leading and trailing spaces are dropped.
// Any other character, ASCII or not, is kept.
#include <string>
#include <string_view>

#include <geode/primal/model.hpp>

namespace geode::io {

std::string sanitize_name(std::string_view name);
// Every block, node set and side set name of the model.
void sanitize_names(primal::Model& model);

}  // namespace geode::io
