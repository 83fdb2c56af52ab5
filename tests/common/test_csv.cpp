// The one CSV writer: header, number formatting as an ostream's, quoting, append without a
// second header, row width checked, write errors named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/csv.hpp"

namespace auvrl::csv {
namespace {

std::string read_all(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string temp_path(const char* name) {
  return (std::filesystem::temp_directory_path() / name).string();
}

TEST(CsvWriter, WritesHeaderNumbersAsAnOstreamAndQuotesOnlyWhatNeedsIt) {
  const std::string path = temp_path("auvrl_csv_test.csv");
  {
    Writer w(path, {"a", "b", "c", "d"});
    w.row(0.1 + 0.2, 42, std::string("plain"), "with, comma");
    w.cell(1e-7).empty().cell(true).cell("say \"hi\"");
    w.end_row();
    w.flush();
    EXPECT_EQ(w.rows(), 2);
  }
  std::ostringstream expected_number;
  expected_number << 0.1 + 0.2 << "," << 1e-7;  // the ostream default: 6 significant digits
  EXPECT_EQ(expected_number.str(), "0.3,1e-07");
  EXPECT_EQ(read_all(path), "a,b,c,d\n0.3,42,plain,\"with, comma\"\n1e-07,,1,\"say \"\"hi\"\"\"\n");
  std::filesystem::remove(path);
}

TEST(CsvWriter, SignificantDigitsAreTheFilesChoice) {
  const std::string path = temp_path("auvrl_csv_digits.csv");
  {
    Writer w(path, {"x"}, Mode::kTruncate, 9);
    w.row(3.14159265358979);
  }
  EXPECT_EQ(read_all(path), "x\n3.14159265\n");
  std::filesystem::remove(path);
}

// The files that moved onto the writer (evaluation 9 digits, searches and open loop 17) read
// the same as when an ostream with setprecision wrote them.
TEST(CsvWriter, NumbersMatchAnOstreamAtEveryPrecisionUsed) {
  const double values[] = {0.0,       -0.0,          1.0,          -7.0,          0.1 + 0.2,
                           1.0 / 3.0, 1e-7,          123456789.0,  6.02e23,       -2.5e-300,
                           8.1,       119.344006123, 1e300 * 10.0, -1e300 * 10.0, 4.9e-324};
  for (int digits : {6, 9, 17}) {
    const std::string path = temp_path("auvrl_csv_precision.csv");
    std::ostringstream expected;
    expected.precision(digits);
    expected << "x\n";
    {
      Writer w(path, {"x"}, Mode::kTruncate, digits);
      for (double v : values) {
        w.row(v);
        expected << v << '\n';
      }
      w.flush();
    }
    EXPECT_EQ(read_all(path), expected.str()) << digits;
    std::filesystem::remove(path);
  }
}

TEST(CsvWriter, FixedCellsKeepTheirDecimals) {
  const std::string path = temp_path("auvrl_csv_fixed.csv");
  {
    Writer w(path, {"t", "rate"});
    w.row(Fixed{12.0, 3}, Fixed{0.04999, 1});
  }
  EXPECT_EQ(read_all(path), "t,rate\n12.000,0.0\n");
  std::filesystem::remove(path);
}

TEST(CsvWriter, AppendWritesTheHeaderOnlyOnce) {
  const std::string path = temp_path("auvrl_csv_append.csv");
  std::filesystem::remove(path);
  for (int i = 0; i < 2; ++i) {
    Writer w(path, {"i"}, Mode::kAppend);
    w.row(i);
  }
  EXPECT_EQ(read_all(path), "i\n0\n1\n");
  std::filesystem::remove(path);
}

TEST(CsvWriter, ARowOfTheWrongWidthAndAnUnwritablePathAreErrorsNamingTheFile) {
  const std::string path = temp_path("auvrl_csv_width.csv");
  Writer w(path, {"a", "b"});
  w.cell(1);
  try {
    w.end_row();
    FAIL() << "a row of 1 cell under 2 columns was accepted";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  try {
    Writer bad("/nonexistent-dir/x.csv", {"a"});
    FAIL() << "opened a file in a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.csv"), std::string::npos);
  }
  std::filesystem::remove(path);
}

TEST(CsvQuote, DoublesQuotesAndKeepsPlainCellsAsTheyAre) {
  EXPECT_EQ(quote("abc"), "abc");
  EXPECT_EQ(quote("a\"b"), "\"a\"\"b\"");
  EXPECT_EQ(quote("line\nbreak"), "\"line\nbreak\"");
}

}  // namespace
}  // namespace auvrl::csv
