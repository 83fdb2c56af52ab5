// One declaration per setting: a config::Table<T> lists each key of a configuration struct
// with its member (or accessor), unit or range and a one-line doc, and drives the YAML reader
// (unknown keys and wrong types are errors naming file, dotted key and line), the command-line
// flags (key `replay_capacity` <-> --replay-capacity), their --help text and
// docs/configuration.md. The struct's own member initialisers are the defaults.
#pragma once

#include <Eigen/Core>
#include <cctype>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/config/yaml_config.hpp"

namespace auvrl::config {

/// Text conversions of a setting's type: its name in the docs, its value as text (defaults,
/// --help) and its value parsed from a command-line argument (throws std::invalid_argument).
template <class V>
struct Codec;

#define AUVRL_CONFIG_CODEC(V, NAME)            \
  template <>                                  \
  struct Codec<V> {                            \
    static const char* type() { return NAME; } \
    static std::string show(const V& value);   \
    static V parse(const std::string& text);   \
  }
AUVRL_CONFIG_CODEC(double, "number");
AUVRL_CONFIG_CODEC(float, "number");
AUVRL_CONFIG_CODEC(int, "integer");
AUVRL_CONFIG_CODEC(std::int64_t, "integer");
AUVRL_CONFIG_CODEC(std::uint64_t, "integer >= 0");
AUVRL_CONFIG_CODEC(bool, "bool");
AUVRL_CONFIG_CODEC(std::string, "string");
AUVRL_CONFIG_CODEC(std::vector<int>, "list of integers");
AUVRL_CONFIG_CODEC(Eigen::Vector3d, "[x, y, z]");
AUVRL_CONFIG_CODEC(std::vector<std::vector<double>>, "list of lists of numbers");
#undef AUVRL_CONFIG_CODEC

/// A number as show() wrote it, back (strtod: never throws, even on a denormal).
double shown_number(const std::string& text);

/// "[1, 2, 3]" (shortest round-trip numbers).
std::string show_numbers(const double* values, int n);
/// Exactly n numbers ("1,2,3" or "[1, 2, 3]"); throws std::invalid_argument.
void parse_numbers(const std::string& text, double* out, int n);
/// An n x n column-major matrix as its diagonal "[a, b, c]" when the rest is zero, else rows.
std::string show_square(const double* values, int n);
/// n rows of n numbers or the n numbers of the diagonal; throws std::invalid_argument.
void parse_square(const std::string& text, double* out, int n);

/// A fixed-size vector of N numbers (Eigen::Vector3d has its own "[x, y, z]" above).
template <int N>
struct Codec<Eigen::Matrix<double, N, 1>> {
  static std::string type() { return "list of " + std::to_string(N) + " numbers"; }
  static std::string show(const Eigen::Matrix<double, N, 1>& v) {
    return show_numbers(v.data(), N);
  }
  static Eigen::Matrix<double, N, 1> parse(const std::string& text) {
    Eigen::Matrix<double, N, 1> v;
    parse_numbers(text, v.data(), N);
    return v;
  }
};

/// An N x N matrix: N rows of N numbers, or its diagonal as N numbers.
template <int N>
struct Codec<Eigen::Matrix<double, N, N>> {
  static std::string type() {
    const std::string n = std::to_string(N);
    return n + "x" + n + " matrix: " + n + " rows, or the diagonal alone";
  }
  static std::string show(const Eigen::Matrix<double, N, N>& m) { return show_square(m.data(), N); }
  static Eigen::Matrix<double, N, N> parse(const std::string& text) {
    Eigen::Matrix<double, N, N> m;
    parse_square(text, m.data(), N);
    return m;
  }
};

/// One row of the generated documentation.
struct FieldDoc {
  std::string key;  ///< dotted within its section ("scales.position_m")
  std::string type;
  std::string default_text;
  std::string unit;  ///< unit and/or allowed range
  std::string doc;
  bool required = false;  ///< no default: the key must be given
};

/// The command-line flag of a key: `replay_capacity` -> `replay-capacity`, `scales.depth_m` ->
/// `scales-depth-m`.
std::string flag_name(const std::string& key);

/// One setting of T, type-erased: how to read it from YAML, parse it from text, show it and
/// check its range.
template <class T>
struct Field {
  std::string key, type, unit, doc;
  bool is_bool = false;   ///< a --flag without a value (sets true)
  bool required = false;  ///< absent is an error
  std::function<void(Section&, T&)> read;
  std::function<void(const std::string&, T&)> parse;
  std::function<std::string(T&)> show;
  /// An error message when the value is out of range; empty when it is fine.
  std::function<std::string(T&)> check;
  /// A sub-map (task.scales) or the entries of a list of maps (thrusters[].name): its keys,
  /// prefixed. Entries of a list have no parse (they get no flag).
  std::vector<Field<T>> children;
};

/// The settings of a configuration struct T, in the order they are documented.
template <class T>
class Table {
 public:
  /// name: the YAML section (e.g. "learner"); doc: one line about it.
  Table(std::string name, std::string doc) : name_(std::move(name)), doc_(std::move(doc)) {}

  /// A member (`&T::x`) or an accessor (`[](T& t) -> M& { return t.a.x; }`) of a type that
  /// Codec knows.
  template <class Access>
  Table& field(const std::string& key, Access access, const std::string& unit,
               const std::string& doc) {
    auto get = accessor(access);
    using M = std::remove_reference_t<decltype(get(std::declval<T&>()))>;
    Field<T> f = base(key, Codec<M>::type(), unit, doc);
    f.is_bool = std::is_same_v<M, bool>;
    f.read = [get, key](Section& s, T& t) { s.read(key, get(t)); };
    f.parse = [get](const std::string& text, T& t) { get(t) = Codec<M>::parse(text); };
    f.show = [get](T& t) { return Codec<M>::show(get(t)); };
    fields_.push_back(std::move(f));
    return *this;
  }

  /// An enum written as text: parse throws std::invalid_argument naming the choices.
  template <class Access, class E>
  Table& choice(const std::string& key, Access access, E (*parse)(const std::string&),
                const char* (*show)(E), const std::string& choices, const std::string& doc) {
    auto get = accessor(access);
    Field<T> f = base(key, "text", choices, doc);
    f.read = [get, key, parse, show](Section& s, T& t) {
      std::string text = show(get(t));
      s.read(key, text);
      try {
        get(t) = parse(text);
      } catch (const std::exception& e) {
        s.fail(key, e.what());
      }
    };
    f.parse = [get, parse](const std::string& text, T& t) { get(t) = parse(text); };
    f.show = [get, show](T& t) { return std::string(show(get(t))); };
    fields_.push_back(std::move(f));
    return *this;
  }

  /// A value written as text with its own conversions: parse (text -> M, throws
  /// std::invalid_argument or another std::exception) and show (M -> text).
  template <class Access, class Parse, class Show>
  Table& text_field(const std::string& key, Access access, Parse parse, Show show,
                    const std::string& type, const std::string& unit, const std::string& doc) {
    auto get = accessor(access);
    Field<T> f = base(key, type, unit, doc);
    f.read = [get, key, parse](Section& s, T& t) {
      if (!s.has(key)) return s.ignore_key(key);
      std::string text;
      s.read(key, text);
      try {
        get(t) = parse(text);
      } catch (const std::exception& e) {
        s.fail(key, e.what());
      }
    };
    f.parse = [get, parse](const std::string& text, T& t) { get(t) = parse(text); };
    f.show = [get, show](T& t) { return std::string(show(get(t))); };
    fields_.push_back(std::move(f));
    return *this;
  }

  /// The last field must be present (vehicle files: no defaults).
  Table& required() {
    fields_.back().required = true;
    return *this;
  }

  /// The last field must lie in [lo, hi]; checked on reading a file and on a flag.
  Table& range(double lo, double hi = std::numeric_limits<double>::infinity()) {
    Field<T>& f = fields_.back();
    const std::string text = range_text(lo, hi);
    f.unit = f.unit.empty() ? text : f.unit + ", " + text;
    auto show = f.show;
    f.check = [show, text, lo, hi](T& t) {
      const double v = shown_number(show(t));
      return v >= lo && v <= hi ? std::string() : "expected " + text + ", got " + show(t);
    };
    return *this;
  }

  /// The last field must be > 0 (a step, a mass); checked on reading a file and on a flag.
  Table& positive() {
    Field<T>& f = fields_.back();
    f.unit = f.unit.empty() ? "> 0" : f.unit + ", > 0";
    auto show = f.show;
    f.check = [show](T& t) {
      return shown_number(show(t)) > 0 ? std::string() : "expected > 0, got " + show(t);
    };
    return *this;
  }

  /// A check across fields, run once all are read: fn(section, target) calls section.fail(key,
  /// what) on a bad combination (e.g. keys that exclude each other).
  Table& validate(std::function<void(const Section&, T&)> fn) {
    validators_.push_back(std::move(fn));
    return *this;
  }

  /// Every field of another table, at this level (a struct inside T whose keys share T's map).
  template <class U, class Access>
  Table& include(const Table<U>& other, Access access) {
    auto get = accessor(access);
    for (const Field<U>& f : other.fields()) fields_.push_back(lift(f, get, ""));
    for (const auto& v : other.validators()) {
      validators_.push_back([v, get](const Section& s, T& t) { v(s, get(t)); });
    }
    return *this;
  }

  /// Another table as a sub-map under key (documented and flagged as key.sub).
  template <class U, class Access>
  Table& section(const std::string& key, const Table<U>& other, Access access) {
    auto get = accessor(access);
    Field<T> group = base(key, "map", "", other.doc());
    group.read = [key, other, get](Section& s, T& t) { other.read(s.child(key), get(t)); };
    for (const Field<U>& f : other.fields()) group.children.push_back(lift(f, get, key + "."));
    fields_.push_back(std::move(group));
    return *this;
  }

  /// A list of maps under key, each entry read by other into a U (a fresh U{} each) and the
  /// list stored through access (T& -> std::vector<U>&); it must have min_items..max_items
  /// entries. Documented as key[].sub; its keys get no flags.
  template <class U, class Access>
  Table& list(const std::string& key, const Table<U>& other, Access access,
              std::size_t min_items = 0,
              std::size_t max_items = std::numeric_limits<std::size_t>::max()) {
    auto get = accessor(access);
    Field<T> group = base(key, "list of maps", "", other.doc());
    group.read = [key, other, get, min_items, max_items](Section& s, T& t) {
      std::vector<U> entries;
      for (Section& item : s.items(key, min_items, max_items)) {
        U entry{};
        other.read(item, entry);
        entries.push_back(std::move(entry));
      }
      if (s.has(key)) get(t) = std::move(entries);
    };
    for (const Field<U>& f : other.fields()) group.children.push_back(entry(f, key + "[]."));
    fields_.push_back(std::move(group));
    return *this;
  }

  /// Reads the fields present in the section without finishing it (keys nobody asked for stay
  /// unreported: for a section shared with other readers).
  void read_keys(Section& section, T& target) const {
    for (const Field<T>& f : fields_) {
      if (f.required && !section.has(f.key)) section.fail(f.key, "missing");
      f.read(section, target);
      if (f.check && section.has(f.key)) {
        const std::string error = f.check(target);
        if (!error.empty()) section.fail(f.key, error);
      }
    }
    for (const auto& validate : validators_) validate(section, target);
  }

  /// Reads the section into target and rejects unknown keys.
  void read(Section section, T& target) const {
    read_keys(section, target);
    section.finish();
  }

  /// Registers --key flags on cmd (cli::CommandLine's option API) bound to target; the
  /// target's current values are the defaults shown. A bool gets --key (true) and --no-key
  /// (false). Keys in skip get no flag.
  template <class CommandLineT>
  void add_flags(CommandLineT& cmd, T& target, const std::set<std::string>& skip = {}) const {
    for (const Field<T>& f : flat()) {
      if (skip.count(f.key) != 0 || !f.parse) continue;
      const std::string help = f.unit.empty() ? f.doc : f.doc + " [" + f.unit + "]";
      if (f.is_bool) {
        cmd.custom_flag(
            flag_name(f.key), [&target, f] { f.parse("true", target); },
            help + " (default: " + f.show(target) + ")");
        cmd.custom_flag(
            "no-" + flag_name(f.key), [&target, f] { f.parse("false", target); },
            "sets " + f.key + " false");
        continue;
      }
      cmd.custom_option(
          flag_name(f.key),
          [&target, f](const std::string& text) {
            f.parse(text, target);
            if (f.check) {
              const std::string error = f.check(target);
              if (!error.empty()) throw std::invalid_argument(error);
            }
          },
          f.show(target), help, upper(f.type));
    }
  }

  /// A field's type as --help shows it ("number" -> "NUMBER").
  static std::string upper(std::string text) {
    for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return text;
  }

  /// The documentation rows, defaults from a default-constructed T.
  std::vector<FieldDoc> docs() const {
    T defaults{};
    std::vector<FieldDoc> rows;
    for (const Field<T>& f : flat())
      rows.push_back({f.key, f.type, f.show(defaults), f.unit, f.doc, f.required});
    return rows;
  }

  const std::string& name() const { return name_; }
  const std::string& doc() const { return doc_; }
  const std::vector<Field<T>>& fields() const { return fields_; }
  const std::vector<std::function<void(const Section&, T&)>>& validators() const {
    return validators_;
  }

 private:
  template <class Access>
  static auto accessor(Access access) {
    if constexpr (std::is_member_object_pointer_v<Access>) {
      return [access](T & t) -> auto& { return t.*access; };
    } else {
      return access;
    }
  }

  static Field<T> base(const std::string& key, std::string type, const std::string& unit,
                       const std::string& doc) {
    Field<T> f;
    f.key = key;
    f.type = std::move(type);
    f.unit = unit;
    f.doc = doc;
    return f;
  }

  /// A field of U seen through get (T& -> U&), its key prefixed.
  template <class U, class Get>
  static Field<T> lift(const Field<U>& f, Get get, const std::string& prefix) {
    Field<T> out = base(prefix + f.key, f.type, f.unit, f.doc);
    out.is_bool = f.is_bool;
    out.required = f.required;
    if (f.read) out.read = [r = f.read, get](Section& s, T& t) { r(s, get(t)); };
    if (f.parse) out.parse = [p = f.parse, get](const std::string& text, T& t) { p(text, get(t)); };
    out.show = [s = f.show, get](T& t) { return s(get(t)); };
    if (f.check) out.check = [c = f.check, get](T& t) { return c(get(t)); };
    for (const Field<U>& child : f.children) out.children.push_back(lift(child, get, prefix));
    return out;
  }

  /// A field of a list entry (U) for the docs: shown from a default U, never read or parsed.
  template <class U>
  static Field<T> entry(const Field<U>& f, const std::string& prefix) {
    Field<T> out = base(prefix + f.key, f.type, f.unit, f.doc);
    out.required = f.required;
    out.show = [s = f.show](T&) {
      U defaults{};
      return s(defaults);
    };
    for (const Field<U>& child : f.children) out.children.push_back(entry(child, prefix));
    return out;
  }

  /// Fields with sub-maps and lists expanded into their keys, at any depth.
  std::vector<Field<T>> flat() const { return flatten(fields_); }
  static std::vector<Field<T>> flatten(const std::vector<Field<T>>& fields) {
    std::vector<Field<T>> out;
    for (const Field<T>& f : fields) {
      if (f.children.empty()) {
        out.push_back(f);
      } else {
        const std::vector<Field<T>> inner = flatten(f.children);
        out.insert(out.end(), inner.begin(), inner.end());
      }
    }
    return out;
  }

  static std::string range_text(double lo, double hi);

  std::string name_;
  std::string doc_;
  std::vector<Field<T>> fields_;
  std::vector<std::function<void(const Section&, T&)>> validators_;
};

/// ">= lo", "<= hi" or "lo..hi" (shortest round-trip numbers).
std::string format_range(double lo, double hi);

template <class T>
std::string Table<T>::range_text(double lo, double hi) {
  return format_range(lo, hi);
}

/// One section of docs/configuration.md: its heading, summary and rows.
struct SectionDoc {
  std::string name;
  std::string doc;
  std::vector<FieldDoc> rows;
};

/// The section's documentation from its table.
template <class T>
SectionDoc section_doc(const Table<T>& table) {
  return {table.name(), table.doc(), table.docs()};
}

/// docs/configuration.md: a Markdown table per section.
std::string render_markdown(const std::vector<SectionDoc>& sections, const std::string& preamble);

}  // namespace auvrl::config
