#include "address_prefix.h"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cstdlib>
#include <cstring>

namespace plinth::firmware {

namespace {

// The peer's address bytes and family, an IPv4-mapped IPv6 address as IPv4.
int peer_bytes(const sockaddr_storage& peer, std::array<std::uint8_t, 16>& out) {
  if (peer.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(peer);
    std::memcpy(out.data(), &v4.sin_addr, 4);
    return AF_INET;
  }
  if (peer.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(peer);
    if (IN6_IS_ADDR_V4MAPPED(&v6.sin6_addr)) {
      std::memcpy(out.data(), v6.sin6_addr.s6_addr + 12, 4);
      return AF_INET;
    }
    std::memcpy(out.data(), v6.sin6_addr.s6_addr, 16);
    return AF_INET6;
  }
  return AF_UNSPEC;
}

// Whether the first `bits` bits of `a` and `b` agree.
bool same_prefix(const std::array<std::uint8_t, 16>& a, const std::array<std::uint8_t, 16>& b,
                 int bits) {
  for (int i = 0; i < bits / 8; ++i) {
    if (a[static_cast<std::size_t>(i)] != b[static_cast<std::size_t>(i)]) return false;
  }
  const int rest = bits % 8;
  if (rest == 0) return true;
  const auto mask = static_cast<std::uint8_t>(0xFF << (8 - rest));
  const auto at = static_cast<std::size_t>(bits / 8);
  return (a[at] & mask) == (b[at] & mask);
}

}  // namespace

bool AddressPrefix::contains(const sockaddr_storage& peer) const {
  std::array<std::uint8_t, 16> address{};
  return peer_bytes(peer, address) == family && same_prefix(address, bytes, bits);
}

bool AddressPrefix::same_address(const sockaddr_storage& a, const sockaddr_storage& b) {
  std::array<std::uint8_t, 16> first{};
  std::array<std::uint8_t, 16> second{};
  const int family = peer_bytes(a, first);
  return family != AF_UNSPEC && family == peer_bytes(b, second) && first == second;
}

std::optional<AddressPrefix> parse_address_prefix(const std::string& text) {
  AddressPrefix p;
  p.text = text;
  const std::size_t slash = text.find('/');
  const std::string address = text.substr(0, slash);
  if (inet_pton(AF_INET, address.c_str(), p.bytes.data()) == 1) {
    p.family = AF_INET;
    p.bits = 32;
  } else if (inet_pton(AF_INET6, address.c_str(), p.bytes.data()) == 1) {
    p.family = AF_INET6;
    p.bits = 128;
  } else {
    return std::nullopt;
  }
  if (slash != std::string::npos) {
    const std::string digits = text.substr(slash + 1);
    if (digits.empty() || digits.size() > 3 ||
        digits.find_first_not_of("0123456789") != std::string::npos) {
      return std::nullopt;
    }
    const int bits = std::atoi(digits.c_str());
    if (bits > p.bits) return std::nullopt;
    p.bits = bits;
  }
  // No bit set past the prefix: "10.0.4.7/24" is a typo for one address or a network.
  std::array<std::uint8_t, 16> host = p.bytes;
  for (int i = p.bits; i < (p.family == AF_INET ? 32 : 128); ++i) {
    host[static_cast<std::size_t>(i / 8)] &= static_cast<std::uint8_t>(~(0x80 >> (i % 8)));
  }
  if (host != p.bytes) return std::nullopt;
  return p;
}

std::string peer_text(const sockaddr_storage& peer) {
  char address[INET6_ADDRSTRLEN] = "?";
  std::string out;
  if (peer.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(peer);
    inet_ntop(AF_INET, &v4.sin_addr, address, sizeof address);
    out.append(address).append(":").append(std::to_string(ntohs(v4.sin_port)));
  } else if (peer.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(peer);
    inet_ntop(AF_INET6, &v6.sin6_addr, address, sizeof address);
    out.append("[").append(address).append("]:").append(std::to_string(ntohs(v6.sin6_port)));
  } else {
    out = "(unknown address)";
  }
  return out;
}

}  // namespace plinth::firmware
