#include "common/config/yaml_config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <ios>
#include <iterator>
#include <limits>

namespace auvrl::config {

Section::Section(std::string file, std::string path, YAML::Node node)
    : file_(std::move(file)), path_(std::move(path)), node_(std::move(node)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    const std::string detail =
        "must be a map of keys (line " + std::to_string(node_.Mark().line + 1) + ")";
    throw ConfigError(
        file_ + ": '" + (path_.empty() ? std::string("top level") : path_) + "' " + detail, path_,
        detail);
  }
}

std::string Section::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void Section::fail(const std::string& key, const std::string& what) const {
  std::string where;
  const YAML::Node n = node_.IsMap() ? node_[key] : YAML::Node();
  if (n.IsDefined() && n.Mark().line >= 0) {
    where = " (line " + std::to_string(n.Mark().line + 1) + ")";
  } else if (!path_.empty() && node_.IsMap() && node_.Mark().line >= 0) {
    // An absent key: point at the block it belongs in.
    where = " (in the block '" + path_ + "' starting at line " +
            std::to_string(node_.Mark().line + 1) + ")";
  }
  throw ConfigError(file_ + ": '" + key_path(key) + "': " + what + where, key_path(key),
                    what + where);
}

bool Section::has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

std::optional<YAML::Node> Section::get(const std::string& key) {
  read_.insert(key);
  if (!has(key)) return std::nullopt;
  return node_[key];
}

double Section::number(const YAML::Node& node, const std::string& key) const {
  double v = 0;
  try {
    if (!node.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "expected a number");
  }
  if (!std::isfinite(v)) fail(key, "expected a finite number");
  return v;
}

std::int64_t Section::integer(const YAML::Node& node, const std::string& key) const {
  try {
    if (!node.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    return node.as<std::int64_t>();
  } catch (const YAML::Exception&) {
    fail(key,
         "expected an integer, got '" + (node.IsScalar() ? node.Scalar() : "a list or map") + "'");
  }
}

void Section::read(const std::string& key, double& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    value = number(n, key);
  }
}

void Section::read(const std::string& key, float& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    const double v = number(n, key);
    if (std::abs(v) > std::numeric_limits<float>::max()) fail(key, "out of range");
    value = static_cast<float>(v);
  }
}

void Section::read(const std::string& key, int& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    const std::int64_t v = integer(n, key);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
      fail(key, "out of range");
    }
    value = static_cast<int>(v);
  }
}

void Section::read(const std::string& key, std::int64_t& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    value = integer(n, key);
  }
}

void Section::read(const std::string& key, std::uint64_t& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    const std::int64_t v = integer(n, key);
    if (v < 0) fail(key, "expected a non-negative integer");
    value = static_cast<std::uint64_t>(v);
  }
}

void Section::read(const std::string& key, bool& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    try {
      value = n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(key, "expected true or false");
    }
  }
}

void Section::read(const std::string& key, std::string& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    if (!n.IsScalar()) fail(key, "expected a string");
    value = n.Scalar();
  }
}

void Section::read(const std::string& key, std::vector<int>& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    if (!n.IsSequence()) fail(key, "expected a list of integers");
    std::vector<int> out;
    for (const auto& item : n) {
      const std::int64_t v = integer(item, key);
      if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
        fail(key, "out of range");
      }
      out.push_back(static_cast<int>(v));
    }
    value = out;
  }
}

void Section::read_numbers(const std::string& key, double* out, int n) {
  if (const auto found = get(key)) {
    const YAML::Node& node = *found;
    if (!node.IsSequence() || static_cast<int>(node.size()) != n) {
      fail(key, fmt::format("expected a list of {} numbers{}", n,
                            node.IsSequence() ? fmt::format(", got {}", node.size()) : ""));
    }
    for (int i = 0; i < n; ++i) out[i] = number(node[i], key);
  }
}

void Section::read_square(const std::string& key, double* out, int n) {
  if (const auto found = get(key)) {
    const YAML::Node& node = *found;
    const std::string expected =
        fmt::format("expected {0} rows of {0} numbers, or the {0} numbers of the diagonal", n);
    if (!node.IsSequence() || static_cast<int>(node.size()) != n) fail(key, expected);
    std::fill(out, out + n * n, 0.0);
    if (node[0].IsScalar()) {
      for (int i = 0; i < n; ++i) {
        if (!node[i].IsScalar()) fail(key, expected);
        out[i * n + i] = number(node[i], key);
      }
      return;
    }
    for (int r = 0; r < n; ++r) {
      const YAML::Node row = node[r];
      if (!row.IsSequence() || static_cast<int>(row.size()) != n) fail(key, expected);
      for (int c = 0; c < n; ++c) out[c * n + r] = number(row[c], key);
    }
  }
}

void Section::read(const std::string& key, std::vector<std::vector<double>>& value) {
  if (const auto found = get(key)) {
    const YAML::Node& n = *found;
    if (!n.IsSequence()) fail(key, "expected a list of lists of numbers");
    std::vector<std::vector<double>> out;
    for (const auto& row : n) {
      if (!row.IsSequence()) fail(key, "expected a list of lists of numbers");
      std::vector<double> r;
      for (const auto& item : row) r.push_back(number(item, key));
      out.push_back(r);
    }
    value = out;
  }
}

Section Section::child(const std::string& key) {
  const auto found = get(key);
  return Section(file_, key_path(key), found ? *found : YAML::Node());
}

std::vector<Section> Section::items(const std::string& key, std::size_t min_items,
                                    std::size_t max_items) {
  std::vector<Section> out;
  const auto found = get(key);
  if (!found) return out;
  const YAML::Node& node = *found;
  if (!node.IsSequence()) fail(key, "expected a list of maps");
  if (node.size() < min_items) {
    fail(key, fmt::format("expected at least {} {}, got {}", min_items,
                          min_items == 1 ? "entry" : "entries", node.size()));
  }
  if (node.size() > max_items) {
    fail(key, fmt::format("expected at most {} entries, got {}", max_items, node.size()));
  }
  for (std::size_t i = 0; i < node.size(); ++i) {
    out.emplace_back(file_, fmt::format("{}[{}]", key_path(key), i), node[i]);
  }
  return out;
}

void Section::ignore(std::initializer_list<const char*> keys) {
  for (const char* k : keys) read_.insert(k);
}

void Section::finish() const {
  if (!node_.IsMap()) return;
  for (const auto& entry : node_) {
    // A complex key ("? [a, b]: ...") is valid YAML but no name (found by fuzz_run_config).
    if (!entry.first.IsScalar()) {
      const std::string detail =
          "expected names as keys (line " + std::to_string(entry.first.Mark().line + 1) + ")";
      throw ConfigError(
          file_ + ": '" + (path_.empty() ? std::string("top level") : path_) + "': " + detail,
          path_, detail);
    }
    const std::string key = entry.first.Scalar();
    if (read_.count(key) == 0) {
      std::string known;
      for (const auto& k : read_) known += (known.empty() ? "" : ", ") + k;
      const std::string detail = "unknown key (line " +
                                 std::to_string(entry.first.Mark().line + 1) +
                                 "; known here: " + known + ")";
      throw ConfigError(file_ + ": '" + key_path(key) + "': " + detail, key_path(key), detail);
    }
  }
}

bool read_text_file(const std::string& path, std::string& text, std::string& why) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    why = "is a directory, not a file";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = "cannot open the file";
    return false;
  }
  try {
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::ios_base::failure& e) {
    why = std::string("cannot read the file: ") + e.what();
    return false;
  }
  if (in.bad()) {
    why = "cannot read the file";
    return false;
  }
  return true;
}

Section load_file(const std::string& path) {
  std::string text;
  std::string why;
  if (!read_text_file(path, text, why)) throw ConfigError(path + ": " + why);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ": not valid YAML: " + e.what());
  }
  return Section(path, "", root);
}

Section load_text(const std::string& text, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
  return Section(origin, "", root);
}

}  // namespace auvrl::config

namespace auvrl::config {

void finish_run_file(Section& root) {
  root.ignore({"vehicle", "task", "schedule", "learner", "actor", "run", "transport", "finetune"});
  root.finish();
}

std::string resolve_path(const Section& section, const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  const auto slash = section.file().rfind('/');
  return slash == std::string::npos ? path : section.file().substr(0, slash + 1) + path;
}

}  // namespace auvrl::config
