// The LCM event-log reader (auv_log and the tools that replay logs): bytes as a log file, read
// to the end by LogReader, which must report damage and never crash or loop.
#include "fuzz/fuzz_util.hpp"
#include "logger/event_log.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::scratch_dir() + "/events.lcmlog";
  fuzz::write_file(path, data, size);
  logger::LogReader reader(path);
  logger::LogEvent event;
  std::uint64_t last_offset = 0;
  std::size_t events = 0;
  while (reader.next(event)) {
    // Events come in file order, each inside the file.
    if (events++ > 0 && event.offset <= last_offset) std::abort();
    if (event.offset + logger::kEventHeaderSize + event.channel.size() + event.data.size() >
        reader.file_size()) {
      std::abort();
    }
    last_offset = event.offset;
  }
  return 0;
}
