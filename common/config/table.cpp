#include "common/config/table.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>

namespace auvrl::config {
namespace {

[[noreturn]] void bad(const std::string& text, const char* expected) {
  throw std::invalid_argument(fmt::format("expected {}, got '{}'", expected, text));
}

double parse_number(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
    bad(text, "a finite number");
  }
  return v;
}

std::int64_t parse_integer(const std::string& text) {
  std::size_t used = 0;
  std::int64_t v = 0;
  try {
    v = std::stoll(text, &used);
  } catch (const std::exception&) {
    bad(text, "an integer");
  }
  if (used != text.size()) bad(text, "an integer");
  return v;
}

/// A YAML flow list ("[1, 2]" or "1, 2") as a node.
YAML::Node parse_list(const std::string& text, const char* expected) {
  try {
    const YAML::Node n = YAML::Load(text.rfind('[', 0) == 0 ? text : "[" + text + "]");
    if (n.IsSequence()) return n;
  } catch (const YAML::Exception&) {
  }
  bad(text, expected);
}

template <class Range>
std::string join(const Range& items) {
  std::string out = "[";
  for (const auto& item : items) out += (out.size() > 1 ? ", " : "") + fmt::format("{}", item);
  return out + "]";
}

std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

}  // namespace

std::string Codec<double>::show(const double& v) { return fmt::format("{}", v); }
double Codec<double>::parse(const std::string& t) { return parse_number(t); }

std::string Codec<float>::show(const float& v) { return fmt::format("{}", v); }
float Codec<float>::parse(const std::string& t) {
  const double v = parse_number(t);
  if (std::abs(v) > std::numeric_limits<float>::max()) bad(t, "a number in float's range");
  return static_cast<float>(v);
}

std::string Codec<int>::show(const int& v) { return fmt::format("{}", v); }
int Codec<int>::parse(const std::string& t) {
  const std::int64_t v = parse_integer(t);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    bad(t, "an integer in int's range");
  }
  return static_cast<int>(v);
}

std::string Codec<std::int64_t>::show(const std::int64_t& v) { return fmt::format("{}", v); }
std::int64_t Codec<std::int64_t>::parse(const std::string& t) { return parse_integer(t); }

std::string Codec<std::uint64_t>::show(const std::uint64_t& v) { return fmt::format("{}", v); }
std::uint64_t Codec<std::uint64_t>::parse(const std::string& t) {
  const std::int64_t v = parse_integer(t);
  if (v < 0) bad(t, "a non-negative integer");
  return static_cast<std::uint64_t>(v);
}

std::string Codec<bool>::show(const bool& v) { return v ? "true" : "false"; }
bool Codec<bool>::parse(const std::string& t) {
  if (t == "true") return true;
  if (t == "false") return false;
  bad(t, "true or false");
}

std::string Codec<std::string>::show(const std::string& v) { return v; }
std::string Codec<std::string>::parse(const std::string& t) { return t; }

std::string Codec<std::vector<int>>::show(const std::vector<int>& v) { return join(v); }
std::vector<int> Codec<std::vector<int>>::parse(const std::string& t) {
  // Hidden sizes are also written 400-300.
  std::string text = t;
  if (text.rfind('[', 0) != 0) {
    for (char& c : text) c = c == '-' ? ',' : c;
  }
  std::vector<int> out;
  for (const auto& item : parse_list(text, "a list of integers such as 400-300 or [400, 300]")) {
    out.push_back(Codec<int>::parse(item.IsScalar() ? item.Scalar() : t));
  }
  return out;
}

std::string Codec<Eigen::Vector3d>::show(const Eigen::Vector3d& v) {
  return join(std::vector<double>{v.x(), v.y(), v.z()});
}
Eigen::Vector3d Codec<Eigen::Vector3d>::parse(const std::string& t) {
  const YAML::Node n = parse_list(t, "three numbers such as 0,0,5 or [0, 0, 5]");
  if (n.size() != 3) bad(t, "three numbers such as 0,0,5 or [0, 0, 5]");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = parse_number(n[i].IsScalar() ? n[i].Scalar() : t);
  return v;
}

std::string Codec<std::vector<std::vector<double>>>::show(
    const std::vector<std::vector<double>>& v) {
  std::string out = "[";
  for (const auto& row : v) out += (out.size() > 1 ? ", " : "") + join(row);
  return out + "]";
}
std::vector<std::vector<double>> Codec<std::vector<std::vector<double>>>::parse(
    const std::string& t) {
  const char* expected = "a list of lists of numbers such as [[0, 1.5], [100, 0.5]]";
  std::vector<std::vector<double>> out;
  for (const auto& row : parse_list(t, expected)) {
    if (!row.IsSequence()) bad(t, expected);
    std::vector<double> r;
    for (const auto& item : row) r.push_back(parse_number(item.IsScalar() ? item.Scalar() : t));
    out.push_back(r);
  }
  return out;
}

std::string flag_name(const std::string& key) {
  std::string out = key;
  for (char& c : out) c = (c == '_' || c == '.') ? '-' : c;
  return out;
}

std::string format_range(double lo, double hi) {
  if (std::isinf(hi)) return fmt::format(">= {}", lo);
  if (std::isinf(lo)) return fmt::format("<= {}", hi);
  return fmt::format("{}..{}", lo, hi);
}

std::string render_markdown(const std::vector<SectionDoc>& sections, const std::string& preamble) {
  std::string out = preamble;
  for (const SectionDoc& s : sections) {
    out += fmt::format("\n## `{}`\n\n{}\n\n", s.name, s.doc);
    out += "| key | type | default | unit / range | doc |\n|---|---|---|---|---|\n";
    for (const FieldDoc& r : s.rows) {
      out += fmt::format("| `{}` | {} | `{}` | {} | {} |\n", r.key, escape(r.type),
                         r.default_text.empty() ? std::string("\"\"") : escape(r.default_text),
                         escape(r.unit), escape(r.doc));
    }
  }
  return out;
}

}  // namespace auvrl::config
