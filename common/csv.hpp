// The one CSV writer: every CSV the system writes (run telemetry, evaluation summaries and
// trajectories, log exports, searches) goes through it, so quoting, number formatting, append
// semantics and write errors are the same everywhere.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace auvrl::csv {

/// How a Writer opens its file.
enum class Mode {
  kTruncate,  ///< a new file: the header, then the rows
  kAppend,    ///< rows added to an existing file; the header only when the file is new or empty
};

/// A number written with a fixed count of decimals (printf's %.Nf), e.g. times in telemetry.
struct Fixed {
  double value;
  int decimals;
};

/// One CSV file written row by row. Numbers are written like printf's %.Ng (N significant
/// digits, 6 by default, as an ostream writes them); text cells are quoted (RFC 4180) only when
/// they hold a comma, a quote or a line break. Every failure throws std::runtime_error naming
/// the file.
class Writer {
 public:
  Writer(std::string path, const std::vector<std::string>& header, Mode mode = Mode::kTruncate,
         int significant_digits = 6);

  Writer& cell(double value);
  Writer& cell(float value) { return cell(static_cast<double>(value)); }
  Writer& cell(Fixed number);
  Writer& cell(std::int64_t value);
  Writer& cell(std::uint64_t value);
  Writer& cell(int value) { return cell(static_cast<std::int64_t>(value)); }
  Writer& cell(bool value) { return cell(static_cast<std::int64_t>(value ? 1 : 0)); }
  Writer& cell(std::string_view text);
  Writer& cell(const char* text) { return cell(std::string_view(text)); }
  Writer& cell(const std::string& text) { return cell(std::string_view(text)); }
  /// An empty cell (a figure that does not exist, e.g. the time to reach of a miss).
  Writer& empty();
  /// Ends the row; throws when the row has another number of cells than the header.
  void end_row();

  /// A whole row at once.
  template <class... Cells>
  void row(const Cells&... cells) {
    (cell(cells), ...);
    end_row();
  }

  /// Flushes to the file; throws naming the file when the write failed (disk full, ...).
  void flush();
  const std::string& path() const { return path_; }
  std::int64_t rows() const { return rows_; }

 private:
  void separator();

  std::string path_;
  std::ofstream out_;
  int digits_;
  std::size_t columns_;
  std::size_t cells_in_row_ = 0;
  std::int64_t rows_ = 0;
};

/// A text cell as CSV writes it: as is, or quoted with inner quotes doubled when it holds a
/// comma, a quote or a line break.
std::string quote(std::string_view text);

}  // namespace auvrl::csv
