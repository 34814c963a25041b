#include "modbus_protocol.h"

namespace plinth::firmware::modbus {

namespace {

constexpr std::size_t kMinLength = 2;    // unit id and function code
constexpr std::size_t kMaxLength = 254;  // unit id and kMaxPduBytes
constexpr std::uint16_t kCoilOn = 0xFF00;
constexpr std::uint16_t kCoilOff = 0x0000;

std::uint16_t word_at(std::span<const std::uint8_t> bytes, std::size_t at) {
  return static_cast<std::uint16_t>(bytes[at] << 8 | bytes[at + 1]);
}

// Writes the answer's PDU after the request's MBAP header (transaction and unit echoed).
class Writer {
 public:
  Writer(std::span<const std::uint8_t> request, std::array<std::uint8_t, kMaxFrameBytes>& out)
      : out_(out) {
    for (std::size_t i = 0; i < kHeaderBytes; ++i) out_[i] = request[i];
  }
  Writer& byte(std::uint8_t value) {
    out_[size_++] = value;
    return *this;
  }
  Writer& word(std::uint16_t value) {
    return byte(static_cast<std::uint8_t>(value >> 8)).byte(static_cast<std::uint8_t>(value));
  }
  // The MBAP length (unit id and PDU) filled in; the frame's bytes.
  std::size_t finish() {
    const std::size_t length = 1 + size_ - kHeaderBytes;
    out_[4] = static_cast<std::uint8_t>(length >> 8);
    out_[5] = static_cast<std::uint8_t>(length);
    return size_;
  }

 private:
  std::array<std::uint8_t, kMaxFrameBytes>& out_;
  std::size_t size_ = kHeaderBytes;
};

Answer exception(std::span<const std::uint8_t> request, std::uint8_t function, Exception code,
                 std::array<std::uint8_t, kMaxFrameBytes>& out) {
  Answer a;
  a.function = function;
  a.exception = code;
  a.bytes = Writer(request, out)
                .byte(static_cast<std::uint8_t>(function | 0x80))
                .byte(static_cast<std::uint8_t>(code))
                .finish();
  return a;
}

bool is_register_write(std::uint8_t function) {
  return function == 0x06 || function == 0x10 || function == 0x16 || function == 0x17;
}

// Functions 01 and 02: `count` bits from `bits` (nullptr: all 0), packed LSB first.
Answer read_bits(std::span<const std::uint8_t> request, const std::uint8_t* bits, int table_size,
                 std::array<std::uint8_t, kMaxFrameBytes>& out) {
  const std::uint8_t function = request[kHeaderBytes];
  const int address = word_at(request, kHeaderBytes + 1);
  const int count = word_at(request, kHeaderBytes + 3);
  if (count < 1 || count > kMaxReadBits) {
    return exception(request, function, Exception::kIllegalDataValue, out);
  }
  if (address + count > table_size) {
    return exception(request, function, Exception::kIllegalDataAddress, out);
  }
  Writer w(request, out);
  w.byte(function).byte(static_cast<std::uint8_t>((count + 7) / 8));
  for (int first = 0; first < count; first += 8) {
    std::uint8_t packed = 0;
    for (int i = 0; i < 8 && first + i < count; ++i) {
      if (bits != nullptr && bits[address + first + i] != 0) {
        packed = static_cast<std::uint8_t>(packed | 1 << i);
      }
    }
    w.byte(packed);
  }
  Answer a;
  a.function = function;
  a.bytes = w.finish();
  return a;
}

Answer read_registers(std::span<const std::uint8_t> request, const Image& image,
                      std::array<std::uint8_t, kMaxFrameBytes>& out) {
  const std::uint8_t function = request[kHeaderBytes];
  const int address = word_at(request, kHeaderBytes + 1);
  const int count = word_at(request, kHeaderBytes + 3);
  if (count < 1 || count > kMaxReadRegisters) {
    return exception(request, function, Exception::kIllegalDataValue, out);
  }
  if (address + count > reg::kCount) {
    return exception(request, function, Exception::kIllegalDataAddress, out);
  }
  Writer w(request, out);
  w.byte(function).byte(static_cast<std::uint8_t>(2 * count));
  for (int i = 0; i < count; ++i) w.word(image.registers[static_cast<std::size_t>(address + i)]);
  Answer a;
  a.function = function;
  a.bytes = w.finish();
  return a;
}

// Functions 05 and 15: the coils written 1 are the commands.
Answer write_coils(std::span<const std::uint8_t> request, bool may_write,
                   std::array<std::uint8_t, kMaxFrameBytes>& out) {
  const std::uint8_t function = request[kHeaderBytes];
  if (!may_write) {
    Answer a = exception(request, function, Exception::kIllegalFunction, out);
    a.write_refused = true;
    return a;
  }
  const int address = word_at(request, kHeaderBytes + 1);
  std::array<bool, coil::kCount> written{};
  if (function == kWriteSingleCoil) {
    const std::uint16_t value = word_at(request, kHeaderBytes + 3);
    if (value != kCoilOn && value != kCoilOff) {
      return exception(request, function, Exception::kIllegalDataValue, out);
    }
    if (address >= coil::kCount) {
      return exception(request, function, Exception::kIllegalDataAddress, out);
    }
    written[static_cast<std::size_t>(address)] = value == kCoilOn;
  } else {
    const int count = word_at(request, kHeaderBytes + 3);
    const int byte_count = request[kHeaderBytes + 5];
    if (count < 1 || count > kMaxWriteCoils || byte_count != (count + 7) / 8) {
      return exception(request, function, Exception::kIllegalDataValue, out);
    }
    if (address + count > coil::kCount) {
      return exception(request, function, Exception::kIllegalDataAddress, out);
    }
    for (int i = 0; i < count; ++i) {
      const std::uint8_t packed = request[kHeaderBytes + 6 + static_cast<std::size_t>(i / 8)];
      written[static_cast<std::size_t>(address + i)] = (packed >> (i % 8) & 1) != 0;
    }
  }
  Answer a;
  a.function = function;
  a.acknowledge = written[coil::kAcknowledge];
  a.reset = written[coil::kReset];
  a.statue_stands = written[coil::kStatueStands];
  // Function 05 echoes the request; 15 answers with the address and the quantity.
  Writer w(request, out);
  w.byte(function);
  for (std::size_t i = 1; i < 5; ++i) w.byte(request[kHeaderBytes + i]);
  a.bytes = w.finish();
  return a;
}

// The PDU length a served function's request must have; 0: not served.
std::size_t request_length(std::span<const std::uint8_t> pdu) {
  switch (pdu[0]) {
    case kReadCoils:
    case kReadDiscreteInputs:
    case kReadHoldingRegisters:
    case kReadInputRegisters:
    case kWriteSingleCoil:
      return 5;
    case kWriteMultipleCoils:
      return pdu.size() < 6 ? 6 : 6 + static_cast<std::size_t>(pdu[5]);
    default:
      return 0;
  }
}

}  // namespace

FrameSpan frame_at(std::span<const std::uint8_t> received) {
  FrameSpan span;
  if (received.size() >= 4 && word_at(received, 2) != 0) {
    span.fault = FrameFault::kProtocolId;
    return span;
  }
  if (received.size() < 6) return span;
  const std::size_t length = word_at(received, 4);
  if (length < kMinLength || length > kMaxLength) {
    span.fault = FrameFault::kLength;
    return span;
  }
  if (received.size() >= 6 + length) span.bytes = 6 + length;
  return span;
}

Answer answer(std::span<const std::uint8_t> request, const Image& image, bool may_write,
              std::array<std::uint8_t, kMaxFrameBytes>& out) {
  const std::span<const std::uint8_t> pdu = request.subspan(kHeaderBytes);
  const std::uint8_t function = pdu[0];
  const std::size_t expected = request_length(pdu);
  if (expected == 0) {
    Answer a = exception(request, function, Exception::kIllegalFunction, out);
    a.write_refused = is_register_write(function);
    return a;
  }
  if (pdu.size() != expected) {
    Answer a;
    a.function = function;
    a.fault = FrameFault::kShape;
    return a;
  }
  switch (function) {
    case kReadCoils:
      return read_bits(request, nullptr, coil::kCount, out);
    case kReadDiscreteInputs:
      return read_bits(request, image.discrete_inputs.data(), discrete::kCount, out);
    case kReadHoldingRegisters:
    case kReadInputRegisters:
      return read_registers(request, image, out);
    default:
      return write_coils(request, may_write, out);
  }
}

}  // namespace plinth::firmware::modbus
