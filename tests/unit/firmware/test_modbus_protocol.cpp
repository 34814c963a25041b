// plinth-monitor's Modbus TCP protocol (firmware/linux/modbus_protocol.h): framing a byte
// stream, what is not Modbus, the exceptions for what the box does not serve, the answers and
// the coils' commands; the peers that may write (address_prefix.h); the text the outputs log
// (log_text.h).
#include <arpa/inet.h>
#include <netinet/in.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "address_prefix.h"
#include "log_text.h"
#include "modbus_protocol.h"

namespace plinth::firmware::modbus {
namespace {

using Bytes = std::vector<std::uint8_t>;

// An MBAP frame: transaction 0x1234, protocol `protocol`, the length of unit + pdu (or
// `length` when given), unit 0x11, then `pdu`.
Bytes frame(const Bytes& pdu, std::uint16_t protocol = 0, int length = -1) {
  const auto n =
      static_cast<std::uint16_t>(length >= 0 ? length : static_cast<int>(pdu.size()) + 1);
  Bytes out;
  out.reserve(kHeaderBytes + pdu.size());
  for (const std::uint8_t b : {std::uint8_t{0x12}, std::uint8_t{0x34},
                               static_cast<std::uint8_t>(protocol >> 8),
                               static_cast<std::uint8_t>(protocol),
                               static_cast<std::uint8_t>(n >> 8), static_cast<std::uint8_t>(n),
                               std::uint8_t{0x11}}) {
    out.push_back(b);
  }
  for (const std::uint8_t b : pdu) out.push_back(b);
  return out;
}

struct Reply {
  Answer answer;
  Bytes bytes;
};

Reply ask(const Bytes& request, bool may_write = false) {
  Image image;
  for (std::size_t i = 0; i < image.registers.size(); ++i) {
    image.registers[i] = static_cast<std::uint16_t>(1000 + i);
  }
  image.discrete_inputs[3] = 1;
  std::array<std::uint8_t, kMaxFrameBytes> out{};
  Reply r;
  r.answer = answer(request, image, may_write, out);
  r.bytes.assign(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(r.answer.bytes));
  return r;
}

TEST(ModbusFraming, AFrameIsWholeOnceItsLengthHasCome) {
  const Bytes f = frame({0x03, 0x00, 0x00, 0x00, 0x02});
  for (std::size_t n = 0; n < f.size(); ++n) {
    const FrameSpan s = frame_at({f.data(), n});
    EXPECT_EQ(s.bytes, 0U) << n;
    EXPECT_EQ(s.fault, FrameFault::kNoFault) << n;
  }
  Bytes two = f;
  two.insert(two.end(), f.begin(), f.end());
  EXPECT_EQ(frame_at(two).bytes, f.size()) << "the first of two frames back to back";
}

// A protocol id other than 0, or a length field outside 2..254, is not Modbus: known from the
// header's first bytes, before any more come.
TEST(ModbusFraming, NotModbusIsToldFromTheHeader) {
  for (const std::uint16_t protocol : {std::uint16_t{1}, std::uint16_t{0xFFFF}}) {
    const Bytes f = frame({0x03, 0x00, 0x00, 0x00, 0x02}, protocol);
    EXPECT_EQ(frame_at({f.data(), 4}).fault, FrameFault::kProtocolId) << protocol;
  }
  for (const int length : {0, 1, 255, 0xFFFF}) {
    const Bytes f = frame({0x03, 0x00, 0x00, 0x00, 0x02}, 0, length);
    EXPECT_EQ(frame_at({f.data(), 6}).fault, FrameFault::kLength) << length;
  }
}

// A served function whose length does not match its request (a length field that says more or
// less than the function's data) is refused, not answered.
TEST(ModbusFraming, ALengthThatDoesNotMatchTheFunctionIsRefused) {
  EXPECT_EQ(ask(frame({0x03, 0x00, 0x00, 0x00, 0x02, 0x00})).answer.fault, FrameFault::kShape);
  EXPECT_EQ(ask(frame({0x03, 0x00, 0x00, 0x00})).answer.fault, FrameFault::kShape);
  EXPECT_EQ(ask(frame({0x0F, 0x00, 0x00, 0x00, 0x02, 0x01, 0x03, 0x00})).answer.fault,
            FrameFault::kShape)
      << "a byte count of 1 and 2 data bytes";
  EXPECT_EQ(ask(frame({0x0F, 0x00, 0x00})).answer.fault, FrameFault::kShape);
  EXPECT_EQ(ask(frame({0x0F, 0x00, 0x00, 0x00, 0x02, 0x01, 0x03}), true).answer.fault,
            FrameFault::kNoFault);
}

TEST(ModbusAnswer, ReadsRegistersHighByteFirst) {
  const Reply r = ask(frame({0x04, 0x00, 0x05, 0x00, 0x02}));
  EXPECT_EQ(r.answer.exception, Exception::kNoException);
  EXPECT_EQ(r.bytes, (Bytes{0x12, 0x34, 0, 0, 0, 7, 0x11, 0x04, 4, 0x03, 0xED, 0x03, 0xEE}));
  EXPECT_EQ(ask(frame({0x03, 0x00, 0x05, 0x00, 0x02})).bytes[9], 0x03) << "holding = input";
}

TEST(ModbusAnswer, ReadsBitsPackedFirstBitLowest) {
  EXPECT_EQ(ask(frame({0x02, 0x00, 0x00, 0x00, 0x05})).bytes,
            (Bytes{0x12, 0x34, 0, 0, 0, 4, 0x11, 0x02, 1, 0x08}))
      << "discrete input 3 (alarm) is 1";
  EXPECT_EQ(ask(frame({0x01, 0x00, 0x00, 0x00, 0x02})).bytes,
            (Bytes{0x12, 0x34, 0, 0, 0, 4, 0x11, 0x01, 1, 0x00}))
      << "coils read 0";
}

// Every function the box does not serve is answered with exception 01 (0x11 gives no library
// version, 0x07 no status), a bad quantity or value with 03, an address past the map with 02.
TEST(ModbusAnswer, WhatIsNotServedIsAnExceptionNotASilence) {
  for (const int code : {0x07, 0x08, 0x11, 0x14, 0x18, 0x2B, 0x41, 0x7F}) {
    const auto function = static_cast<std::uint8_t>(code);
    const Reply r = ask(frame({function, 0x00}));
    EXPECT_EQ(r.answer.fault, FrameFault::kNoFault) << int(function);
    EXPECT_EQ(r.bytes, (Bytes{0x12, 0x34, 0, 0, 0, 3, 0x11,
                              static_cast<std::uint8_t>(function | 0x80), 0x01}))
        << int(function);
  }
  EXPECT_EQ(ask(frame({0x03, 0x00, 0x00, 0x00, 0x00})).answer.exception,
            Exception::kIllegalDataValue)
      << "quantity 0";
  EXPECT_EQ(ask(frame({0x03, 0x00, 0x00, 0x00, 126})).answer.exception,
            Exception::kIllegalDataValue);
  EXPECT_EQ(ask(frame({0x01, 0x00, 0x00, 0x07, 0xD1})).answer.exception,
            Exception::kIllegalDataValue)
      << "2001 coils";
  EXPECT_EQ(ask(frame({0x04, 0x00, reg::kCount - 1, 0x00, 0x02})).answer.exception,
            Exception::kIllegalDataAddress);
  EXPECT_EQ(ask(frame({0x02, 0x00, 0x04, 0x00, 0x02})).answer.exception,
            Exception::kIllegalDataAddress);
  // Function 15 with 2000 coils: the most one request may write is 1968 (their 250 bytes do
  // not fit a frame: frame_at refuses its length); 1969 coils fit (247 bytes), and are refused.
  EXPECT_EQ(ask(frame({0x0F, 0x00, 0x00, 0x07, 0xD0, 0x01, 0xFF}), true).answer.exception,
            Exception::kIllegalDataValue);
  Bytes many = {0x0F, 0x00, 0x00, 0x07, 0xB1, 247};
  many.resize(6 + 247, 0xFF);
  EXPECT_EQ(frame_at(frame(many)).bytes, kHeaderBytes + 6 + 247);
  EXPECT_EQ(ask(frame(many), true).answer.exception, Exception::kIllegalDataValue);
  EXPECT_EQ(ask(frame({0x0F, 0x00, 0x00, 0x07, 0xD0, 0x01, 0xFF}), false).answer.exception,
            Exception::kIllegalFunction)
      << "a client that may not write: the function is not served to it";
  EXPECT_EQ(ask(frame({0x05, 0x00, 0x00, 0x12, 0x34}), true).answer.exception,
            Exception::kIllegalDataValue)
      << "a coil value other than 0xFF00 or 0";
  EXPECT_EQ(ask(frame({0x05, 0x00, 0x03, 0xFF, 0x00}), true).answer.exception,
            Exception::kIllegalDataAddress)
      << "coils 0-2 only";
}

TEST(ModbusAnswer, WritesAreCommandsOnlyFromAWriter) {
  const Bytes acknowledge = frame({0x05, 0x00, 0x00, 0xFF, 0x00});
  const Reply refused = ask(acknowledge, false);
  EXPECT_EQ(refused.answer.exception, Exception::kIllegalFunction);
  EXPECT_TRUE(refused.answer.write_refused);
  EXPECT_FALSE(refused.answer.acknowledge);
  const Reply taken = ask(acknowledge, true);
  EXPECT_EQ(taken.bytes, acknowledge) << "function 05 echoes its request";
  EXPECT_TRUE(taken.answer.acknowledge);
  EXPECT_FALSE(taken.answer.reset);
  EXPECT_FALSE(ask(frame({0x05, 0x00, 0x00, 0x00, 0x00}), true).answer.acknowledge)
      << "writing 0 does nothing";
  const Reply both = ask(frame({0x0F, 0x00, 0x00, 0x00, 0x02, 0x01, 0x03}), true);
  EXPECT_TRUE(both.answer.acknowledge && both.answer.reset);
  EXPECT_EQ(both.bytes, (Bytes{0x12, 0x34, 0, 0, 0, 6, 0x11, 0x0F, 0, 0, 0, 2}));
  EXPECT_FALSE(both.answer.statue_stands);
  const Reply stands = ask(frame({0x05, 0x00, 0x02, 0xFF, 0x00}), true);
  EXPECT_TRUE(stands.answer.statue_stands) << "coil 2: the statue stands";
  EXPECT_FALSE(stands.answer.acknowledge || stands.answer.reset);
  EXPECT_FALSE(ask(frame({0x05, 0x00, 0x02, 0xFF, 0x00}), false).answer.statue_stands)
      << "not from a client that may not write";
  for (const int code : {0x06, 0x10, 0x16, 0x17}) {
    const auto function = static_cast<std::uint8_t>(code);
    const Reply r = ask(frame({function, 0x00, 0x00, 0x00, 0x01}), true);
    EXPECT_EQ(r.answer.exception, Exception::kIllegalFunction) << int(function);
    EXPECT_TRUE(r.answer.write_refused) << "registers are read-only: " << int(function);
  }
}

sockaddr_storage peer(const char* text) {
  sockaddr_storage s{};
  if (std::strchr(text, ':') == nullptr) {
    auto& v4 = reinterpret_cast<sockaddr_in&>(s);
    v4.sin_family = AF_INET;
    EXPECT_EQ(inet_pton(AF_INET, text, &v4.sin_addr), 1) << text;
  } else {
    auto& v6 = reinterpret_cast<sockaddr_in6&>(s);
    v6.sin6_family = AF_INET6;
    EXPECT_EQ(inet_pton(AF_INET6, text, &v6.sin6_addr), 1) << text;
  }
  return s;
}

TEST(AddressPrefix, AddressesAndNetworks) {
  const auto one = parse_address_prefix("10.0.4.7");
  ASSERT_TRUE(one);
  EXPECT_TRUE(one->contains(peer("10.0.4.7")));
  EXPECT_FALSE(one->contains(peer("10.0.4.8")));
  EXPECT_TRUE(one->contains(peer("::ffff:10.0.4.7"))) << "a dual-stack socket's IPv4 peer";
  const auto net = parse_address_prefix("10.0.4.0/23");
  ASSERT_TRUE(net);
  EXPECT_TRUE(net->contains(peer("10.0.5.200")));
  EXPECT_FALSE(net->contains(peer("10.0.6.1")));
  const auto v6 = parse_address_prefix("fd00:1::/32");
  ASSERT_TRUE(v6);
  EXPECT_TRUE(v6->contains(peer("fd00:1:ffff::1")));
  EXPECT_FALSE(v6->contains(peer("fd00:2::1")));
  EXPECT_FALSE(v6->contains(peer("10.0.4.7")));
  EXPECT_TRUE(parse_address_prefix("0.0.0.0/0")->contains(peer("192.0.2.1")));
  for (const char* bad : {"", "10.0.4", "10.0.4.7/24", "10.0.4.0/33", "10.0.4.0/", "::1/129",
                          "host.example", "10.0.4.0/2x", "10.0.4.7 "}) {
    EXPECT_FALSE(parse_address_prefix(bad)) << bad;
  }
}

TEST(LogText, PayloadsCannotForgeALine) {
  EXPECT_EQ(printable("ok {\"a\": 1}"), "ok {\"a\": 1}");
  EXPECT_EQ(printable("a\nplinth-monitor: forged\r\x1b[31m\\"),
            "a\\x0Aplinth-monitor: forged\\x0D\\x1B[31m\\\\");
  EXPECT_EQ(printable("\xff\xc3\xa9"), "\\xFF\\xC3\\xA9");
  EXPECT_EQ(printable(std::string(300, 'x'), 10), "xxxxxxxxxx... (300 bytes)");
  EXPECT_EQ(printable(std::string("a\0b", 3)), "a\\x00b");
}

TEST(LogText, Utf8) {
  EXPECT_TRUE(valid_utf8("hall-3 \xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80"));
  for (const char* bad : {"\xff", "\xc3", "\xc0\xaf", "\xe0\x80\xaf", "\xed\xa0\x80",
                          "\xf4\x90\x80\x80", "a\xe2\x82"}) {
    EXPECT_FALSE(valid_utf8(bad)) << printable(bad);
  }
}

TEST(LogText, ABurstIsBoundedAndCounted) {
  LogLimiter limiter("test", 3, 10.0);
  int said = 0;
  for (int i = 0; i < 100; ++i) said += limiter.say("line", i * 1'000'000) ? 1 : 0;
  EXPECT_EQ(said, 3);
  EXPECT_EQ(limiter.not_shown(), 97U);
  EXPECT_TRUE(limiter.say("after the period", 11'000'000'000));
}

}  // namespace
}  // namespace plinth::firmware::modbus
