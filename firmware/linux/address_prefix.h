// Network addresses and prefixes as a box file lists them ("10.0.4.7", "10.0.4.0/24",
// "fd00::/8"): the Modbus server's modbus.write_from. Host code: allocates.
#pragma once

#include <sys/socket.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace plinth::firmware {

struct AddressPrefix {
  int family = AF_INET;  // AF_INET or AF_INET6
  std::array<std::uint8_t, 16> bytes{};  // the address, network order (4 bytes for IPv4)
  int bits = 32;                         // the prefix length: 0..32 (IPv4), 0..128 (IPv6)
  std::string text;                      // as given

  // Whether `peer` (an accepted connection's address) lies in this prefix; an IPv4-mapped IPv6
  // peer (::ffff:a.b.c.d, a dual-stack socket's) counts as its IPv4 address.
  [[nodiscard]] bool contains(const sockaddr_storage& peer) const;

  // Whether two peers are one host (ports aside; an IPv4-mapped IPv6 address as its IPv4).
  [[nodiscard]] static bool same_address(const sockaddr_storage& a, const sockaddr_storage& b);
};

// "ADDRESS" or "ADDRESS/BITS", IPv4 dotted or IPv6 (inet_pton); nothing when it is neither, or
// a host bit is set past the prefix ("10.0.4.7/24": say 10.0.4.0/24 or 10.0.4.7).
[[nodiscard]] std::optional<AddressPrefix> parse_address_prefix(const std::string& text);

// "127.0.0.1:40222", "[::1]:40222": a peer for messages.
[[nodiscard]] std::string peer_text(const sockaddr_storage& peer);

}  // namespace plinth::firmware
