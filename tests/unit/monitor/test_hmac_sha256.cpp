// SHA-256 and HMAC-SHA256 (hmac_sha256.h) against the published vectors: FIPS 180-4's examples
// and RFC 4231's test cases (their keys, shorter than 32 bytes, zero-padded as HMAC pads them).
#include "plinth/monitor/hmac_sha256.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

namespace plinth::monitor {
namespace {

std::string hex(const Sha256Digest& d) {
  std::string out;
  char two[3];
  for (const std::uint8_t b : d) {
    std::snprintf(two, sizeof two, "%02x", b);
    out += two;
  }
  return out;
}

Sha256Digest sha(const std::string& text) {
  Sha256 h;
  h.update(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
  return h.finish();
}

TEST(Sha256, FipsExamples) {
  EXPECT_EQ(hex(sha("abc")), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(hex(sha("")), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(hex(sha("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // A million 'a', fed in uneven pieces: the block boundary falls inside a piece.
  Sha256 h;
  const std::string piece(997, 'a');
  std::size_t fed = 0;
  while (fed < 1'000'000) {
    const std::size_t n = std::min(piece.size(), 1'000'000 - fed);
    h.update(reinterpret_cast<const std::uint8_t*>(piece.data()), n);
    fed += n;
  }
  EXPECT_EQ(hex(h.finish()), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

Sha256Digest hmac(const std::string& key, const std::string& message) {
  std::array<std::uint8_t, 32> k{};
  std::memcpy(k.data(), key.data(), key.size());
  const ByteSpan part{reinterpret_cast<const std::uint8_t*>(message.data()), message.size()};
  return hmac_sha256(k, &part, 1);
}

TEST(HmacSha256, Rfc4231) {
  EXPECT_EQ(hex(hmac(std::string(20, '\x0b'), "Hi There")),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
  EXPECT_EQ(hex(hmac("Jefe", "what do ya want for nothing?")),
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
  EXPECT_EQ(hex(hmac(std::string(20, '\xaa'), std::string(50, '\xdd'))),
            "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe");
}

TEST(HmacSha256, APartedMessageIsTheWhole) {
  std::array<std::uint8_t, 32> key{};
  key[0] = 7;
  const std::string whole = "origin bytesalert bytes1234";
  const ByteSpan one{reinterpret_cast<const std::uint8_t*>(whole.data()), whole.size()};
  const ByteSpan parts[] = {{one.bytes, 12}, {one.bytes + 12, 11}, {one.bytes + 23, 4}};
  EXPECT_EQ(hmac_sha256(key, parts, 3), hmac_sha256(key, &one, 1));
  const Sha256Digest a = hmac_sha256(key, &one, 1);
  Sha256Digest b = a;
  EXPECT_TRUE(same_bytes(a.data(), b.data(), a.size()));
  b[31] ^= 1;
  EXPECT_FALSE(same_bytes(a.data(), b.data(), a.size()));
}

}  // namespace
}  // namespace plinth::monitor
