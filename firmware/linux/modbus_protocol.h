// Modbus TCP as plinth-monitor serves it, without a library: the MBAP framing of a client's
// byte stream and the answer to each request (Modbus Application Protocol v1.1b3; Messaging on
// TCP/IP v1.0b). The box serves functions 01-05 and 15 on its map (modbus_map.h); every other
// function is answered with exception 01, a bad quantity or value with 03, an address past the
// map with 02, and a frame that is not Modbus (protocol id not 0, a length outside 2..254 or
// that does not match its function's request) is not answered: the server closes that
// connection. Pure: bytes in, bytes out (the sockets are modbus_server.h's). Host code.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "modbus_map.h"
#include "plinth/core/name_table.h"

namespace plinth::firmware::modbus {

inline constexpr std::size_t kHeaderBytes = 7;   // MBAP: transaction, protocol, length, unit
inline constexpr std::size_t kMaxPduBytes = 253;  // function code and data
inline constexpr std::size_t kMaxFrameBytes = kHeaderBytes + kMaxPduBytes;  // 260

// Why a frame is not Modbus.
enum class FrameFault : std::uint8_t {
  kNoFault = 0,
  kProtocolId,  // the MBAP protocol identifier is not 0
  kLength,      // the MBAP length is outside 2..254 (unit id, function code, <= 252 bytes)
  kShape,       // a served function's request whose length does not match its data
};
inline constexpr NameTable<FrameFault, 4> kFrameFaultNames{{{
    {FrameFault::kNoFault, "none"},
    {FrameFault::kProtocolId, "protocol id not 0"},
    {FrameFault::kLength, "length field outside 2..254"},
    {FrameFault::kShape, "length does not match the function's request"},
}}};

// The frame at the front of a client's bytes.
struct FrameSpan {
  std::size_t bytes = 0;  // the complete frame's length; 0 while more bytes are needed
  FrameFault fault = FrameFault::kNoFault;  // known as soon as the header's bytes say so
};
[[nodiscard]] FrameSpan frame_at(std::span<const std::uint8_t> received);

enum class Exception : std::uint8_t {
  kNoException = 0,
  kIllegalFunction = 1,     // not served (or a write this client may not make)
  kIllegalDataAddress = 2,  // past the map
  kIllegalDataValue = 3,    // a quantity or a coil value out of range
};

// Function codes the box serves, and the register writes it refuses by name.
inline constexpr std::uint8_t kReadCoils = 0x01;
inline constexpr std::uint8_t kReadDiscreteInputs = 0x02;
inline constexpr std::uint8_t kReadHoldingRegisters = 0x03;
inline constexpr std::uint8_t kReadInputRegisters = 0x04;
inline constexpr std::uint8_t kWriteSingleCoil = 0x05;
inline constexpr std::uint8_t kWriteMultipleCoils = 0x0F;
// The spec's bounds of one request's quantity.
inline constexpr int kMaxReadBits = 2000;       // functions 01, 02
inline constexpr int kMaxReadRegisters = 125;   // functions 03, 04
inline constexpr int kMaxWriteCoils = 1968;     // function 15

// What came of one request.
struct Answer {
  FrameFault fault = FrameFault::kNoFault;  // another: no answer; close the connection
  std::size_t bytes = 0;                 // of the answer written to `out`
  std::uint8_t function = 0;
  Exception exception = Exception::kNoException;
  bool write_refused = false;  // a register write, or a coil write this client may not make
  bool acknowledge = false;    // coil 0 written 1
  bool reset = false;          // coil 1 written 1
  bool statue_stands = false;  // coil 2 written 1
};

// Answers the complete frame `request` (frame_at()'s bytes) from `image` into `out`; coil
// writes only when `may_write` (else exception 01). Coils read 0: a write is a command, not a
// stored value.
[[nodiscard]] Answer answer(std::span<const std::uint8_t> request, const Image& image,
                            bool may_write, std::array<std::uint8_t, kMaxFrameBytes>& out);

}  // namespace plinth::firmware::modbus
