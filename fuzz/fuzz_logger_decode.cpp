// The logger's schema-driven decoder (what auv_log export/filter/summary and the logger's
// summary run on every logged message): one raw message against the schema of the project's
// own .lcm files, then every decoded column formatted as the CSV export formats it.
#include "fuzz/fuzz_util.hpp"
#include "logger/decode.hpp"
#include "logger/schema.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const logger::Schema schema =
      logger::Schema::from_directories({logger::default_types_dir()});
  // The first byte picks the option (blobs or one column per byte); the rest is the message.
  if (size == 0) return 0;
  logger::DecodeOptions options;
  options.byte_arrays_as_blobs = (data[0] & 1) != 0;
  logger::DecodedMessage message;
  std::string error;
  if (logger::decode_message(schema, data + 1, size - 1, message, error, options) ==
      logger::DecodeStatus::kOk) {
    for (const logger::FieldValue& field : message.fields) {
      (void)logger::format_value(field);
      (void)logger::column_order_key(*message.type, field.name);
    }
  }
  return 0;
}
