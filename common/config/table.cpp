#include "common/config/table.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
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

std::string show_numbers(const double* values, int n) {
  return join(std::vector<double>(values, values + n));
}

void parse_numbers(const std::string& text, double* out, int n) {
  const std::string expected = fmt::format("{} numbers such as 1,2,3 or [1, 2, 3]", n);
  const YAML::Node list = parse_list(text, expected.c_str());
  if (static_cast<int>(list.size()) != n) bad(text, expected.c_str());
  for (int i = 0; i < n; ++i) {
    if (!list[i].IsScalar()) bad(text, expected.c_str());
    out[i] = parse_number(list[i].Scalar());
  }
}

std::string show_square(const double* values, int n) {
  bool diagonal = true;
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) diagonal = diagonal && (r == c || values[c * n + r] == 0.0);
  }
  std::vector<double> row(static_cast<std::size_t>(n));
  if (diagonal) {
    for (int i = 0; i < n; ++i) row[static_cast<std::size_t>(i)] = values[i * n + i];
    return join(row);
  }
  std::string out = "[";
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) row[static_cast<std::size_t>(c)] = values[c * n + r];
    out += (r > 0 ? ", " : "") + join(row);
  }
  return out + "]";
}

void parse_square(const std::string& text, double* out, int n) {
  const std::string expected =
      fmt::format("{0} rows of {0} numbers or the {0} numbers of the diagonal", n);
  const YAML::Node list = parse_list(text, expected.c_str());
  if (static_cast<int>(list.size()) != n) bad(text, expected.c_str());
  std::fill(out, out + n * n, 0.0);
  const bool diagonal = list[0].IsScalar();
  for (int r = 0; r < n; ++r) {
    if (diagonal) {
      if (!list[r].IsScalar()) bad(text, expected.c_str());
      out[r * n + r] = parse_number(list[r].Scalar());
      continue;
    }
    if (!list[r].IsSequence() || static_cast<int>(list[r].size()) != n) bad(text, expected.c_str());
    for (int c = 0; c < n; ++c) {
      if (!list[r][c].IsScalar()) bad(text, expected.c_str());
      out[c * n + r] = parse_number(list[r][c].Scalar());
    }
  }
}

std::string flag_name(const std::string& key) {
  std::string out = key;
  for (char& c : out) c = (c == '_' || c == '.') ? '-' : c;
  return out;
}

double shown_number(const std::string& text) { return std::strtod(text.c_str(), nullptr); }

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
      const std::string value =
          r.default_text.empty() ? std::string("\"\"") : escape(r.default_text);
      out += fmt::format("| `{}` | {} | {} | {} | {} |\n", r.key, escape(r.type),
                         r.required ? std::string("required") : "`" + value + "`", escape(r.unit),
                         escape(r.doc));
    }
  }
  return out;
}

}  // namespace auvrl::config
