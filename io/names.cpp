#include <geode/io/names.hpp>

#include <geode/primal/utf8.hpp>

namespace geode::io {

using primal::utf8_length;

std::string sanitize_name(std::string_view name) {
  std::string out;
  out.reserve(name.size());
  for (std::size_t i = 0; i < name.size();) {
    const std::size_t n = utf8_length(name, i);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
      continue;
    }
    if (n == 1) {
      const auto c = static_cast<unsigned char>(name[i]);
      out += c < 0x20 || c == 0x7F ? ' ' : c == '"' ? '\'' : static_cast<char>(c);
    } else {
      out.append(name.substr(i, n));
    }
    i += n;
  }
  const std::size_t first = out.find_first_not_of(' ');
  if (first == std::string::npos) return {};
  return out.substr(first, out.find_last_not_of(' ') - first + 1);
}

void sanitize_names(primal::Model& model) {
  for (auto& [id, name] : model.block_names) name = sanitize_name(name);
  for (auto& set : model.node_sets) set.name = sanitize_name(set.name);
  for (auto& set : model.side_sets) set.name = sanitize_name(set.name);
}

}  // namespace geode::io
