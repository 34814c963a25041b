#include "relay_gpiod.h"

#include <gpiod.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "plinth/host/input_error.h"

namespace plinth::firmware {
namespace {

constexpr const char* kConsumer = "plinth-monitor";  // what gpioinfo shows as the lines' user

class GpiodRelays final : public RelayBackend {
 public:
  explicit GpiodRelays(const RelaySettings& settings)
      : chip_name_(settings.chip), chip_(gpiod_chip_open_lookup(settings.chip.c_str())) {
    if (chip_ == nullptr) {
      throw host::InputError("relays.chip: cannot open GPIO chip '" + settings.chip +
                             "': " + std::strerror(errno));
    }
    const unsigned int count = gpiod_chip_num_lines(chip_.get());
    for (std::size_t i = 0; i < kRelayCount; ++i) {
      const RelayLine& wired = settings.lines[i];
      if (wired.offset < 0) continue;
      const std::string key = std::string("relays.") + kRelayNames[i];
      if (static_cast<unsigned int>(wired.offset) >= count) {
        throw host::InputError(key + ": line " + std::to_string(wired.offset) + " is beyond " +
                               chip_name_ + "'s " + std::to_string(count) + " lines");
      }
      gpiod_line* line = gpiod_chip_get_line(chip_.get(), static_cast<unsigned int>(wired.offset));
      const int flags = wired.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
      if (line == nullptr || gpiod_line_request_output_flags(line, kConsumer, flags, 0) != 0) {
        throw host::InputError(key + ": cannot request " + chip_name_ + " line " +
                               std::to_string(wired.offset) +
                               " as an output: " + std::strerror(errno));
      }
      lines_.push_back(line);
    }
  }
  bool set(std::size_t index, bool energised) override {
    return gpiod_line_set_value(lines_.at(index), energised ? 1 : 0) == 0;
  }

 private:
  std::string chip_name_;
  struct CloseChip {
    void operator()(gpiod_chip* chip) const { gpiod_chip_close(chip); }  // releases its lines
  };
  std::unique_ptr<gpiod_chip, CloseChip> chip_;
  std::vector<gpiod_line*> lines_;
};

}  // namespace

std::unique_ptr<RelayBackend> open_gpiod_relays(const RelaySettings& settings) {
  return std::make_unique<GpiodRelays>(settings);
}

}  // namespace plinth::firmware
