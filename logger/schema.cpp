#include "logger/schema.hpp"

#include <dirent.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace auvrl::logger {

namespace {

struct PrimitiveInfo {
  const char* name;
  Primitive primitive;
};

constexpr PrimitiveInfo kPrimitives[] = {
    {"int8_t", Primitive::kInt8},    {"int16_t", Primitive::kInt16},
    {"int32_t", Primitive::kInt32},  {"int64_t", Primitive::kInt64},
    {"byte", Primitive::kByte},      {"float", Primitive::kFloat},
    {"double", Primitive::kDouble},  {"string", Primitive::kString},
    {"boolean", Primitive::kBoolean}};

bool lookup_primitive(const std::string& name, Primitive& out) {
  for (const auto& info : kPrimitives) {
    if (name == info.name) {
      out = info.primitive;
      return true;
    }
  }
  return false;
}

/// Integer types lcm-gen accepts as a variable array size.
bool is_dimension_type(const Member& member) {
  return member.is_primitive && member.dimensions.empty() &&
         (member.primitive == Primitive::kInt8 || member.primitive == Primitive::kInt16 ||
          member.primitive == Primitive::kInt32 || member.primitive == Primitive::kInt64);
}

/// lcm-gen's member-name rule: starts with a letter or '_'.
bool is_legal_name(const std::string& name) {
  return !name.empty() &&
         (std::isalpha(static_cast<unsigned char>(name[0])) != 0 || name[0] == '_');
}

// ---- Tokenizer ------------------------------------------------------------------------------

struct Token {
  std::string text;
  int line = 0;
  bool punct = false;  ///< one of { } [ ] ; , =
};

bool is_punct(char c) {
  return c == '{' || c == '}' || c == '[' || c == ']' || c == ';' || c == ',' || c == '=';
}

bool is_word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.' || c == '+' ||
         c == '-';
}

std::vector<Token> tokenize(const std::string& source_name, const std::string& text) {
  std::vector<Token> tokens;
  int line = 1;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (std::isspace(static_cast<unsigned char>(c)) != 0) {
      ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      const int start_line = line;
      i += 2;
      while (i + 1 < text.size() && !(text[i] == '*' && text[i + 1] == '/')) {
        if (text[i] == '\n') ++line;
        ++i;
      }
      if (i + 1 >= text.size()) {
        throw SchemaError(source_name + ":" + std::to_string(start_line) +
                          ": comment '/*' is never closed with '*/'");
      }
      i += 2;
    } else if (is_punct(c)) {
      tokens.push_back({std::string(1, c), line, true});
      ++i;
    } else if (is_word_char(c)) {
      const std::size_t start = i;
      while (i < text.size() && is_word_char(text[i])) ++i;
      tokens.push_back({text.substr(start, i - start), line, false});
    } else {
      throw SchemaError(source_name + ":" + std::to_string(line) + ": unexpected character '" +
                        std::string(1, c) + "' (an .lcm file holds package, struct and const " +
                        "declarations)");
    }
  }
  return tokens;
}

// ---- Parser ---------------------------------------------------------------------------------

/// Recursive-descent parser of the LCM grammar lcm-gen accepts (structs, members with array
/// dimensions, constants, package directives); enums, deprecated in LCM, are refused.
class Parser {
 public:
  Parser(std::string source_name, std::vector<Token> tokens)
      : source_(std::move(source_name)), tokens_(std::move(tokens)) {}

  void parse(std::vector<std::unique_ptr<StructType>>& out) {
    while (pos_ < tokens_.size()) {
      const Token& token = next("'package' or 'struct'");
      if (token.text == "package" && !token.punct) {
        const Token& name = next("a package name");
        if (name.punct || !is_legal_name(name.text)) fail(name, "expected a package name");
        package_ = name.text;
        require(";");
      } else if (token.text == "struct" && !token.punct) {
        out.push_back(parse_struct(token.line));
      } else if (token.text == "enum" && !token.punct) {
        fail(token, "enums are not supported (deprecated in LCM); use a struct with constants");
      } else {
        fail(token, "expected 'package' or 'struct'");
      }
    }
  }

 private:
  [[noreturn]] void fail(const Token& token, const std::string& what) const {
    throw SchemaError(source_ + ":" + std::to_string(token.line) + ": " + what + ", got '" +
                      token.text + "'");
  }
  [[noreturn]] void fail_at_end(const std::string& what) const {
    const int line = tokens_.empty() ? 1 : tokens_.back().line;
    throw SchemaError(source_ + ":" + std::to_string(line) + ": end of file, expected " + what);
  }

  const Token& next(const std::string& what) {
    if (pos_ >= tokens_.size()) fail_at_end(what);
    return tokens_[pos_++];
  }
  const Token* peek() const { return pos_ < tokens_.size() ? &tokens_[pos_] : nullptr; }
  bool try_consume(const char* punct) {
    const Token* token = peek();
    if (token != nullptr && token->punct && token->text == punct) {
      ++pos_;
      return true;
    }
    return false;
  }
  void require(const char* punct) {
    const Token& token = next(std::string("'") + punct + "'");
    if (!token.punct || token.text != punct) fail(token, std::string("expected '") + punct + "'");
  }

  std::string qualify(const std::string& name) const {
    return package_.empty() ? name : package_ + "." + name;
  }

  std::unique_ptr<StructType> parse_struct(int line) {
    auto type = std::make_unique<StructType>();
    const Token& name = next("a struct name");
    if (name.punct || !is_legal_name(name.text) || name.text.find('.') != std::string::npos) {
      fail(name, "expected a struct name");
    }
    type->package = package_;
    type->short_name = name.text;
    type->full_name = qualify(name.text);
    type->source = source_;
    type->line = line;
    require("{");
    while (!try_consume("}")) {
      const Token& first = next("a member, a constant or '}'");
      if (first.punct) fail(first, "expected a member type, 'const' or '}'");
      if (first.text == "const") {
        parse_constants(*type);
      } else if (first.text == "struct" || first.text == "enum") {
        fail(first, "nested declarations are not supported by LCM");
      } else {
        parse_members(*type, first);
      }
    }
    return type;
  }

  bool name_taken(const StructType& type, const std::string& name) const {
    for (const Member& m : type.members) {
      if (m.name == name) return true;
    }
    for (const Constant& c : type.constants) {
      if (c.name == name) return true;
    }
    return false;
  }

  void parse_constants(StructType& type) {
    const Token& type_token = next("a constant type");
    Primitive primitive;
    if (!lookup_primitive(type_token.text, primitive) || primitive == Primitive::kByte ||
        primitive == Primitive::kString || primitive == Primitive::kBoolean) {
      fail(type_token,
           "expected a constant type (int8_t, int16_t, int32_t, int64_t, float, double)");
    }
    do {
      const Token& name = next("a constant name");
      if (name.punct || !is_legal_name(name.text)) fail(name, "expected a constant name");
      if (name_taken(type, name.text)) fail(name, "duplicate member name in " + type.full_name);
      require("=");
      const Token& value = next("a constant value");
      if (value.punct) fail(value, "expected a constant value");
      char* end = nullptr;
      errno = 0;
      if (primitive == Primitive::kFloat || primitive == Primitive::kDouble) {
        std::strtod(value.text.c_str(), &end);
      } else {
        std::strtoll(value.text.c_str(), &end, 0);
      }
      if (end == value.text.c_str() || *end != '\0' || errno == ERANGE) {
        fail(value, std::string("expected a ") + type_token.text + " value");
      }
      type.constants.push_back({type_token.text, name.text, value.text});
    } while (try_consume(","));
    require(";");
  }

  void parse_members(StructType& type, const Token& type_token) {
    Member proto;
    proto.line = type_token.line;
    if (lookup_primitive(type_token.text, proto.primitive)) {
      proto.is_primitive = true;
      proto.type_name = type_token.text;
    } else {
      if (!is_legal_name(type_token.text)) fail(type_token, "expected a type name");
      proto.type_name = type_token.text.find('.') == std::string::npos ? qualify(type_token.text)
                                                                       : type_token.text;
    }
    do {
      Member member = proto;
      const Token& name = next("a member name");
      if (name.punct || !is_legal_name(name.text) || name.text.find('.') != std::string::npos) {
        fail(name, "expected a member name (starting with a letter or '_')");
      }
      if (name_taken(type, name.text)) fail(name, "duplicate member name in " + type.full_name);
      member.name = name.text;
      member.line = name.line;
      while (try_consume("[")) {
        const Token& size = next("an array size");
        if (size.punct) fail(size, "expected an array size (a number or an earlier member)");
        Dimension dim;
        dim.size_text = size.text;
        if (std::isdigit(static_cast<unsigned char>(size.text[0])) != 0) {
          char* end = nullptr;
          errno = 0;
          const long long n = std::strtoll(size.text.c_str(), &end, 0);
          if (*end != '\0' || errno == ERANGE || n <= 0) {
            fail(size, "expected a constant array size > 0");
          }
          dim.fixed_size = n;
        } else {
          dim.variable = true;
          for (std::size_t i = 0; i < type.members.size(); ++i) {
            if (type.members[i].name == size.text) dim.size_member = static_cast<int>(i);
          }
          if (dim.size_member < 0) {
            fail(size, "array size must be a number or an integer member declared before it");
          }
          if (!is_dimension_type(type.members[dim.size_member])) {
            fail(size, "array size member must be a scalar int8_t, int16_t, int32_t or int64_t");
          }
        }
        require("]");
        member.dimensions.push_back(dim);
      }
      type.members.push_back(std::move(member));
    } while (try_consume(","));
    require(";");
  }

  std::string source_;
  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  std::string package_;
};

// ---- Hashing (lcmgen.c) ---------------------------------------------------------------------

/// lcm-gen: v = ((v << 8) ^ (v >> 55)) + c on int64_t with an arithmetic shift and a signed
/// char c. Done here on unsigned integers so that overflow is defined.
std::uint64_t hash_update(std::uint64_t v, std::int64_t c_as_char) {
  std::uint64_t shifted = v >> 55;
  if ((v >> 63) != 0) shifted |= ~std::uint64_t{0} << 9;  // the sign bit fills from the left
  const auto c = static_cast<std::int8_t>(static_cast<std::uint8_t>(c_as_char & 0xff));
  return ((v << 8) ^ shifted) + static_cast<std::uint64_t>(static_cast<std::int64_t>(c));
}

std::uint64_t hash_string_update(std::uint64_t v, const std::string& s) {
  v = hash_update(v, static_cast<std::int64_t>(s.size()));
  for (const char c : s) v = hash_update(v, static_cast<std::int64_t>(c));
  return v;
}

/// lcm-gen's _computeHash: the base hash plus the nested types' hashes (0 for a type already
/// on the path, which breaks cycles), rotated left by one bit.
std::uint64_t recursive_hash(const StructType& type, std::vector<const StructType*>& path) {
  if (std::find(path.begin(), path.end(), &type) != path.end()) return 0;
  path.push_back(&type);
  std::uint64_t hash = type.base_hash;
  for (const Member& member : type.members) {
    if (!member.is_primitive) hash += recursive_hash(*member.nested, path);
  }
  path.pop_back();
  return (hash << 1) + ((hash >> 63) & 1);
}

constexpr std::uint64_t kSizeCap = std::uint64_t{1} << 62;

std::uint64_t saturating_multiply(std::uint64_t a, std::uint64_t b) {
  if (a == 0 || b == 0) return 0;
  if (a > kSizeCap / b) return kSizeCap;
  return a * b;
}

std::uint64_t min_size(const StructType& type, std::vector<const StructType*>& path) {
  if (std::find(path.begin(), path.end(), &type) != path.end()) return 0;
  path.push_back(&type);
  std::uint64_t total = 0;
  for (const Member& member : type.members) {
    std::uint64_t element =
        member.is_primitive ? primitive_min_size(member.primitive) : min_size(*member.nested, path);
    for (const Dimension& dim : member.dimensions) {
      element = dim.variable
                    ? 0
                    : saturating_multiply(element, static_cast<std::uint64_t>(dim.fixed_size));
    }
    total = std::min(kSizeCap, total + element);
  }
  path.pop_back();
  return total;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SchemaError("cannot read LCM type file " + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::uint64_t primitive_min_size(Primitive primitive) {
  switch (primitive) {
    case Primitive::kInt8:
    case Primitive::kByte:
    case Primitive::kBoolean:
      return 1;
    case Primitive::kInt16:
      return 2;
    case Primitive::kInt32:
    case Primitive::kFloat:
      return 4;
    case Primitive::kInt64:
    case Primitive::kDouble:
      return 8;
    case Primitive::kString:
      return 5;  // int32 length (NUL included) and the NUL
  }
  return 1;
}

const char* primitive_name(Primitive primitive) {
  for (const auto& info : kPrimitives) {
    if (info.primitive == primitive) return info.name;
  }
  return "?";
}

std::uint64_t lcm_base_hash(const StructType& type) {
  std::uint64_t v = 0x12345678;
  // As lcm-gen: the struct's own name is not hashed (types can be renamed), nor are nested
  // types' names (their contents enter through the recursive hash).
  for (const Member& member : type.members) {
    v = hash_string_update(v, member.name);
    if (member.is_primitive) v = hash_string_update(v, member.type_name);
    v = hash_update(v, static_cast<std::int64_t>(member.dimensions.size()));
    for (const Dimension& dim : member.dimensions) {
      v = hash_update(v, dim.variable ? 1 : 0);  // lcm-gen: LCM_CONST = 0, LCM_VAR = 1
      v = hash_string_update(v, dim.size_text);
    }
  }
  return v;
}

Schema Schema::from_sources(const std::vector<std::pair<std::string, std::string>>& sources) {
  Schema schema;
  for (const auto& [name, text] : sources) {
    Parser parser(name, tokenize(name, text));
    parser.parse(schema.types_);
  }
  schema.resolve();
  return schema;
}

Schema Schema::from_files(const std::vector<std::string>& paths) {
  std::vector<std::pair<std::string, std::string>> sources;
  for (const std::string& path : paths) sources.emplace_back(path, read_file(path));
  return from_sources(sources);
}

Schema Schema::from_directories(const std::vector<std::string>& directories) {
  std::vector<std::string> paths;
  for (const std::string& dir : directories) {
    DIR* handle = opendir(dir.c_str());
    if (handle == nullptr) {
      throw SchemaError("cannot open the LCM types directory " + dir +
                        " (give the folder of the .lcm files with --types-dir)");
    }
    std::vector<std::string> found;
    while (const dirent* entry = readdir(handle)) {
      const std::string name = entry->d_name;
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".lcm") == 0) {
        found.push_back(dir + "/" + name);
      }
    }
    closedir(handle);
    if (found.empty()) throw SchemaError("no .lcm files in the LCM types directory " + dir);
    std::sort(found.begin(), found.end());
    paths.insert(paths.end(), found.begin(), found.end());
  }
  return from_files(paths);
}

void Schema::resolve() {
  for (const auto& type : types_) {
    const auto [it, inserted] = by_full_name_.emplace(type->full_name, type.get());
    if (!inserted) {
      throw SchemaError(type->source + ":" + std::to_string(type->line) + ": type " +
                        type->full_name + " is already declared in " + it->second->source);
    }
  }
  for (const auto& type : types_) {
    for (Member& member : type->members) {
      if (member.is_primitive) continue;
      const auto found = by_full_name_.find(member.type_name);
      if (found == by_full_name_.end()) {
        throw SchemaError(type->source + ":" + std::to_string(member.line) + ": member '" +
                          member.name + "' of " + type->full_name + " has type " +
                          member.type_name +
                          ", which is neither an LCM primitive nor a type in the files read");
      }
      member.nested = found->second;
    }
    type->base_hash = lcm_base_hash(*type);
  }
  for (const auto& type : types_) {
    std::vector<const StructType*> path;
    type->fingerprint = recursive_hash(*type, path);
    type->min_encoded_size = min_size(*type, path);
    // Types with the same members (names, primitive types, dimensions) have the same
    // fingerprint, as in lcm-gen: they encode and decode identically, so the first one read
    // decodes for all of them and names_for() lists them all.
    by_fingerprint_[type->fingerprint].push_back(type.get());
  }
}

const StructType* Schema::find_by_fingerprint(std::uint64_t fingerprint) const {
  const auto it = by_fingerprint_.find(fingerprint);
  return it == by_fingerprint_.end() ? nullptr : it->second.front();
}

std::string Schema::names_for(std::uint64_t fingerprint) const {
  const auto it = by_fingerprint_.find(fingerprint);
  if (it == by_fingerprint_.end()) return "unknown type " + fingerprint_hex(fingerprint);
  std::string names;
  for (const StructType* type : it->second) {
    if (!names.empty()) names += " or ";
    names += type->full_name;
  }
  return names;
}

const StructType* Schema::find_by_name(const std::string& name) const {
  if (const auto it = by_full_name_.find(name); it != by_full_name_.end()) return it->second;
  const StructType* match = nullptr;
  for (const auto& type : types_) {
    if (type->short_name == name) {
      if (match != nullptr) return nullptr;  // ambiguous across packages
      match = type.get();
    }
  }
  return match;
}

std::string default_types_dir() { return AUVRL_LCMTYPES_DIR; }

std::string fingerprint_hex(std::uint64_t fingerprint) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(fingerprint));
  return text;
}

}  // namespace auvrl::logger
