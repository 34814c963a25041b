// libFuzzer target: the CAN frame decoder, hal/can_codec. Input: identifier (2 bytes, little
// endian), length (1 byte), data (8 bytes). A frame any decode accepts must encode back to the
// same frame: the codec neither loses nor invents bits.
#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "plinth/hal/can_codec.h"

namespace {

namespace can = plinth::hal::can;

template <typename Message>
void round_trip(const can::CanFrame& frame) {
  Message message{};
  if (!can::decode(frame, message).ok()) return;
  can::CanFrame again{};
  plinth::fuzz::check(can::encode(message, again).ok(), "a decoded message encodes");
  plinth::fuzz::check(again.id == frame.id && again.length == frame.length &&
                          again.data == frame.data,
                      "encode(decode(frame)) == frame");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kFrameBytes = 11;
  for (std::size_t at = 0; at + kFrameBytes <= size; at += kFrameBytes) {
    can::CanFrame frame;
    frame.id = static_cast<std::uint32_t>(data[at] | (data[at + 1] << 8));
    frame.length = data[at + 2];
    for (std::size_t i = 0; i < frame.data.size(); ++i) frame.data[i] = data[at + 3 + i];
    (void)can::classify(frame.id);
    round_trip<can::SensorAcceleration>(frame);
    round_trip<can::SensorHeartbeat>(frame);
    round_trip<can::MonitorStatus>(frame);
    round_trip<can::AlarmEvent>(frame);
    round_trip<can::Acknowledge>(frame);
    round_trip<can::CollapseForecast>(frame);
  }
  return 0;
}
