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

/// One row of the generated documentation.
struct FieldDoc {
  std::string key;  ///< dotted within its section ("scales.position_m")
  std::string type;
  std::string default_text;
  std::string unit;  ///< unit and/or allowed range
  std::string doc;
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
  std::vector<Field<T>> children;  ///< a sub-map (task.scales): its keys, prefixed
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
    f.read = [get, key, parse, show](Section& s, T& t) {
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
      const double v = std::stod(show(t));
      return v >= lo && v <= hi ? std::string() : "expected " + text + ", got " + show(t);
    };
    return *this;
  }

  /// Every field of another table, at this level (a struct inside T whose keys share T's map).
  template <class U, class Access>
  Table& include(const Table<U>& other, Access access) {
    for (const Field<U>& f : other.fields()) fields_.push_back(lift(f, accessor(access), ""));
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
      if (skip.count(f.key) != 0) continue;
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
      rows.push_back({f.key, f.type, f.show(defaults), f.unit, f.doc});
    return rows;
  }

  const std::string& name() const { return name_; }
  const std::string& doc() const { return doc_; }
  const std::vector<Field<T>>& fields() const { return fields_; }

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
    if (f.read) out.read = [r = f.read, get](Section& s, T& t) { r(s, get(t)); };
    out.parse = [p = f.parse, get](const std::string& text, T& t) { p(text, get(t)); };
    out.show = [s = f.show, get](T& t) { return s(get(t)); };
    if (f.check) out.check = [c = f.check, get](T& t) { return c(get(t)); };
    for (const Field<U>& child : f.children) out.children.push_back(lift(child, get, prefix));
    return out;
  }

  /// Fields with sub-maps expanded into their keys.
  std::vector<Field<T>> flat() const {
    std::vector<Field<T>> out;
    for (const Field<T>& f : fields_) {
      if (f.children.empty()) {
        out.push_back(f);
      } else {
        out.insert(out.end(), f.children.begin(), f.children.end());
      }
    }
    return out;
  }

  static std::string range_text(double lo, double hi);

  std::string name_;
  std::string doc_;
  std::vector<Field<T>> fields_;
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
