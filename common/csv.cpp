#include "common/csv.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <stdexcept>

namespace auvrl::csv {

Writer::Writer(std::string path, const std::vector<std::string>& header, Mode mode,
               int significant_digits)
    : path_(std::move(path)), digits_(significant_digits), columns_(header.size()) {
  std::error_code ec;
  const bool had_rows = mode == Mode::kAppend && std::filesystem::file_size(path_, ec) > 0 && !ec;
  out_.open(path_, mode == Mode::kAppend ? std::ios::app : std::ios::trunc);
  if (!out_) throw std::runtime_error(path_ + ": cannot open for writing");
  if (!had_rows) {
    for (std::size_t i = 0; i < header.size(); ++i) out_ << (i ? "," : "") << quote(header[i]);
    out_ << '\n';
  }
}

void Writer::separator() {
  if (cells_in_row_++ > 0) out_ << ',';
}

Writer& Writer::cell(double value) {
  separator();
  out_ << fmt::format("{:.{}g}", value, digits_);
  return *this;
}

Writer& Writer::cell(Fixed number) {
  separator();
  out_ << fmt::format("{:.{}f}", number.value, number.decimals);
  return *this;
}

Writer& Writer::cell(std::int64_t value) {
  separator();
  out_ << value;
  return *this;
}

Writer& Writer::cell(std::uint64_t value) {
  separator();
  out_ << value;
  return *this;
}

Writer& Writer::cell(std::string_view text) {
  separator();
  out_ << quote(text);
  return *this;
}

Writer& Writer::empty() {
  separator();
  return *this;
}

void Writer::end_row() {
  if (cells_in_row_ != columns_) {
    throw std::logic_error(
        fmt::format("{}: a row of {} cells under a header of {}", path_, cells_in_row_, columns_));
  }
  out_ << '\n';
  cells_in_row_ = 0;
  ++rows_;
}

void Writer::flush() {
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": write failed");
}

std::string quote(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

}  // namespace auvrl::csv
