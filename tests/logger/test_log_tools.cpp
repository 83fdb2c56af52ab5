// auv_log's commands on logs written here: list counts and names types, export writes one CSV
// per channel with one row per message and the union of columns, filter picks rows by field
// values; damaged logs are read as far as they go and the exit code says they were damaged.
#include <gtest/gtest.h>

#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_logger_test/all_primitives_t.hpp>
#include <auvrl_logger_test/nested_arrays_t.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "child_process.hpp"
#include "common/csv.hpp"
#include "generated_types.hpp"
#include "logger/event_log.hpp"
#include "logger/log_tools.hpp"

namespace {

using namespace auvrl::logger;
namespace fs = std::filesystem;

template <class Msg>
std::vector<std::uint8_t> encode(const Msg& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) rows.push_back(split_csv_line(line));
  return rows;
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  const auto it = std::find(header.begin(), header.end(), name);
  EXPECT_NE(it, header.end()) << name;
  return static_cast<std::size_t>(it - header.begin());
}

class LogTools : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = auvrl::test_support::make_temp_dir("auvrl_log_tools_");
    // 100 commands on two vehicles, 6 thrusters then 8 (a variable array that grows), a
    // state every command, a string-bearing message, and one of a type nobody knows.
    RotatingLogWriter writer(dir_ + "/logs", "lcmlog", 20000);
    for (int i = 0; i < 100; ++i) {
      auvrl_lcm::thruster_cmd_t cmd{};
      cmd.utime = 1000 + i;
      cmd.vehicle_id = i % 2;
      cmd.seq = i;
      cmd.num_thrusters = i < 50 ? 6 : 8;
      cmd.thrust_n.assign(static_cast<std::size_t>(cmd.num_thrusters), 0.5 * i);
      const auto bytes = encode(cmd);
      writer.write("SIM_CMD_" + std::to_string(i % 2), bytes.data(), bytes.size(),
                   1700000000000000 + i * 100000);
      auvrl_lcm::vehicle_state_t state{};
      state.vehicle_id = i % 2;
      state.seq = i;
      state.num_thrusters = 6;
      state.thrust_realised_n.assign(6, -1.0 * i);
      const auto state_bytes = encode(state);
      writer.write("SIM_STATE_" + std::to_string(i % 2), state_bytes.data(), state_bytes.size(),
                   1700000000000000 + i * 100000 + 50);
    }
    auvrl_logger_test::all_primitives_t p{};
    p.s = "comma, \"quote\"";
    const auto p_bytes = encode(p);
    writer.write("PRIMS", p_bytes.data(), p_bytes.size(), 1700000000000000 + 10000000);
    const std::vector<std::uint8_t> unknown = {9, 9, 9, 9, 9, 9, 9, 9, 1, 2, 3};
    writer.write("MYSTERY", unknown.data(), unknown.size(), 1700000000000000 + 10000001);
    writer.close();
    files_ = expand_log_paths({dir_ + "/logs"});
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string dir_;
  std::vector<std::string> files_;
  Schema schema_ = test_types::all_types_schema();
};

TEST_F(LogTools, ListCountsChannelsRatesAndTypes) {
  ASSERT_GT(files_.size(), 1u);  // rotated, so the tools read several files in order
  std::ostringstream out, err;
  EXPECT_EQ(list_logs(files_, schema_, out, err), kExitOk) << err.str();
  const std::string text = out.str();
  EXPECT_NE(text.find("202 events"), std::string::npos) << text;
  // 50 commands 0.2 s apart: 49 intervals over 9.8 s = 5 Hz.
  std::istringstream lines(text);
  std::string line;
  bool found = false;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string channel, events, rate;
    words >> channel >> events >> rate;
    if (channel != "SIM_CMD_0") continue;
    found = true;
    EXPECT_EQ(events, "50") << line;
    EXPECT_EQ(rate, "5.00") << line;
  }
  EXPECT_TRUE(found) << text;
  EXPECT_NE(text.find("auvrl_lcm.thruster_cmd_t"), std::string::npos);
  EXPECT_NE(text.find("auvrl_lcm.vehicle_state_t"), std::string::npos);
  EXPECT_NE(text.find("MYSTERY"), std::string::npos);
  EXPECT_NE(text.find("unknown type 0x0909090909090909"), std::string::npos) << text;
  EXPECT_TRUE(err.str().empty()) << err.str();
}

TEST_F(LogTools, ExportWritesOneRowPerMessageWithTheUnionOfColumns) {
  ExportOptions options;
  options.out_dir = dir_ + "/csv";
  std::ostringstream out, err;
  EXPECT_EQ(export_logs(files_, schema_, options, out, err), kExitOk) << err.str();
  const auto rows = read_csv(options.out_dir + "/SIM_CMD_0.csv");
  ASSERT_EQ(rows.size(), 51u);  // header and 50 messages
  const auto& header = rows[0];
  EXPECT_EQ(header[0], "utime_log_us");
  EXPECT_EQ(header[1], "channel");
  EXPECT_EQ(header[2], "utime");
  // Thrusters 6 and 7 appear only in later messages; they still follow thrust_n[5].
  EXPECT_EQ(column(header, "thrust_n[6]"), column(header, "thrust_n[5]") + 1);
  EXPECT_EQ(column(header, "thrust_n[7]"), header.size() - 1);
  EXPECT_EQ(rows[1][0], "1700000000000000");
  EXPECT_EQ(rows[1][1], "SIM_CMD_0");
  EXPECT_EQ(rows[1][column(header, "thrust_n[6]")], "");     // a 6-thruster message
  EXPECT_EQ(rows[50][column(header, "thrust_n[7]")], "49");  // the last, 0.5 * 98
  EXPECT_EQ(rows[50][column(header, "seq")], "98");
  for (const auto& row : rows) EXPECT_EQ(row.size(), header.size());
  EXPECT_EQ(read_csv(options.out_dir + "/SIM_STATE_1.csv").size(), 51u);
  // Strings with commas and quotes survive the CSV.
  const auto prims = read_csv(options.out_dir + "/PRIMS.csv");
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_EQ(prims[1][column(prims[0], "s")], "comma, \"quote\"");
  // The message of unknown type is skipped and said so.
  EXPECT_FALSE(fs::exists(options.out_dir + "/MYSTERY.csv"));
  EXPECT_NE(err.str().find("1 messages of unknown type 0x0909090909090909 skipped"),
            std::string::npos)
      << err.str();

  // --channels chooses.
  ExportOptions some;
  some.out_dir = dir_ + "/csv2";
  some.channels = "SIM_STATE_.*";
  EXPECT_EQ(export_logs(files_, schema_, some, out, err), kExitOk);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(some.out_dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"SIM_STATE_0.csv", "SIM_STATE_1.csv"}));
}

TEST_F(LogTools, FilterKeepsTheRowsWhoseFieldsMatch) {
  FilterOptions options;
  options.channel = "SIM_CMD_.*";
  options.where = {parse_where("vehicle_id=1"), parse_where("num_thrusters=8.0")};
  options.out_file = dir_ + "/out/episode.csv";
  std::ostringstream out, err;
  EXPECT_EQ(filter_logs(files_, schema_, options, out, err), kExitOk) << err.str();
  const auto rows = read_csv(options.out_file);
  ASSERT_EQ(rows.size(), 26u);  // odd i in 50..99
  const std::size_t vehicle = column(rows[0], "vehicle_id");
  for (std::size_t r = 1; r < rows.size(); ++r) {
    EXPECT_EQ(rows[r][vehicle], "1");
    EXPECT_EQ(rows[r][1], "SIM_CMD_1");
  }
  EXPECT_EQ(rows[1][column(rows[0], "seq")], "51");

  // A misspelt field is an error that lists the columns.
  options.where = {parse_where("vehicle=1")};
  std::ostringstream err2;
  EXPECT_EQ(filter_logs(files_, schema_, options, out, err2), kExitError);
  EXPECT_NE(err2.str().find("field 'vehicle' is not a column"), std::string::npos) << err2.str();
  EXPECT_NE(err2.str().find("vehicle_id"), std::string::npos);
  EXPECT_THROW(parse_where("novalue"), std::invalid_argument);
}

TEST_F(LogTools, DamagedLogsAreReadAsFarAsPossibleAndTheExitCodeSaysSo) {
  // Corrupt the sync word of an event in the middle of the first file and cut the last file.
  std::vector<std::uint8_t> bytes;
  {
    std::ifstream in(files_.front(), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  LogReader reader(files_.front());
  LogEvent event;
  std::vector<std::uint64_t> offsets;
  while (reader.next(event)) offsets.push_back(event.offset);
  ASSERT_GT(offsets.size(), 10u);
  bytes[offsets[5] + 1] ^= 0xff;
  {
    std::ofstream out(files_.front(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  }
  fs::resize_file(files_.back(), fs::file_size(files_.back()) - 3);

  std::ostringstream out, err;
  EXPECT_EQ(list_logs(files_, schema_, out, err), kExitDamaged);
  EXPECT_NE(err.str().find(files_.front() + ": damaged at byte " + std::to_string(offsets[5]) +
                           ": bad sync word"),
            std::string::npos)
      << err.str();
  EXPECT_NE(err.str().find(files_.back() + ": damaged at byte"), std::string::npos);
  EXPECT_NE(out.str().find("200 events"), std::string::npos) << out.str();

  ExportOptions options;
  options.out_dir = dir_ + "/csv";
  std::ostringstream err2;
  EXPECT_EQ(export_logs(files_, schema_, options, out, err2), kExitDamaged);
  // One command lost to the bad sync word; the rest exported.
  const auto cmd0 = read_csv(options.out_dir + "/SIM_CMD_0.csv").size() - 1;
  const auto cmd1 = read_csv(options.out_dir + "/SIM_CMD_1.csv").size() - 1;
  const auto st0 = read_csv(options.out_dir + "/SIM_STATE_0.csv").size() - 1;
  const auto st1 = read_csv(options.out_dir + "/SIM_STATE_1.csv").size() - 1;
  EXPECT_EQ(cmd0 + cmd1 + st0 + st1, 199u);
}

TEST_F(LogTools, MalformedMessagesAreReportedWithTheirPlace) {
  // A thruster_cmd_t whose thruster count promises more than the message holds.
  auvrl_lcm::thruster_cmd_t cmd{};
  cmd.num_thrusters = 2;
  cmd.thrust_n = {1, 2};
  auto bytes = encode(cmd);
  bytes[8 + 20] = 9;
  const std::string path = dir_ + "/bad";
  RotatingLogWriter writer(path, "x", 1 << 20);
  writer.write("SIM_CMD_0", bytes.data(), bytes.size(), 1);
  writer.close();
  ExportOptions options;
  options.out_dir = dir_ + "/csv_bad";
  std::ostringstream out, err;
  EXPECT_EQ(export_logs(writer.files(), schema_, options, out, err), kExitDamaged);
  EXPECT_NE(err.str().find("event 0 at byte 0 on SIM_CMD_0: auvrl_lcm.thruster_cmd_t.thrust_n"),
            std::string::npos)
      << err.str();
}

TEST_F(LogTools, ExportOrdersTwoDimensionalColumnsRowByRow) {
  // A small matrix first, a bigger one later: the header is still row-major.
  RotatingLogWriter writer(dir_ + "/grid", "lcmlog", 1 << 20);
  for (const auto& [rows, cols] : std::vector<std::pair<int, int>>{{1, 1}, {3, 1}, {2, 3}}) {
    auvrl_logger_test::nested_arrays_t n{};
    n.rows = rows;
    n.cols = static_cast<std::int16_t>(cols);
    n.grid.assign(static_cast<std::size_t>(rows),
                  std::vector<double>(static_cast<std::size_t>(cols), 1.0));
    n.mixed.assign(static_cast<std::size_t>(rows), std::vector<std::int64_t>(4, 2));
    n.mixed2.assign(2, std::vector<std::int16_t>(static_cast<std::size_t>(cols), 3));
    n.blob.assign(static_cast<std::size_t>(rows), 4);
    const auto bytes = encode(n);
    writer.write("GRID", bytes.data(), bytes.size(), rows);
  }
  writer.close();
  ExportOptions options;
  options.out_dir = dir_ + "/grid_csv";
  std::ostringstream out, err;
  ASSERT_EQ(export_logs(writer.files(), schema_, options, out, err), kExitOk) << err.str();
  const auto header = read_csv(options.out_dir + "/GRID.csv").at(0);
  std::vector<std::string> grid;
  for (const auto& name : header) {
    if (name.rfind("grid", 0) == 0) grid.push_back(name);
  }
  EXPECT_EQ(grid, (std::vector<std::string>{"grid[0][0]", "grid[0][1]", "grid[0][2]", "grid[1][0]",
                                            "grid[1][1]", "grid[1][2]", "grid[2][0]"}));
  EXPECT_EQ(column(header, "fixed2d[0][0]"), column(header, "grid[2][0]") + 1);
}

TEST(Csv, SplitReadsWhatTheWriterQuotes) {
  const std::vector<std::string> cells{"plain", "a,b", "say \"hi\"", "", "z"};
  std::string line;
  for (const std::string& c : cells) line += (line.empty() ? "" : ",") + auvrl::csv::quote(c);
  EXPECT_EQ(line, "plain,\"a,b\",\"say \"\"hi\"\"\",,z");
  EXPECT_EQ(split_csv_line(line), cells);
  EXPECT_EQ(split_csv_line("1,\"a,b\",\"x\"\"y\",,z"),
            (std::vector<std::string>{"1", "a,b", "x\"y", "", "z"}));
}

}  // namespace
