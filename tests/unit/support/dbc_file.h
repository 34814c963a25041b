// plinth.dbc as the tests read it: the subset of the DBC grammar the file uses, parsed with
// gtest checks of its syntax (tests of the codec and of the firmware's domain <-> wire map).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace plinth::testing {

struct DbcSignal {
  std::string name;
  unsigned start = 0, length = 0;
  char byte_order = '?';  // '1' Intel, '0' Motorola
  char sign = '?';        // '+' unsigned, '-' signed
  double factor = 0, offset = 0, minimum = 0, maximum = 0;
  std::string unit;
};
struct DbcMessage {
  std::string name;
  unsigned dlc = 0;
  std::vector<DbcSignal> signals;
};
struct Dbc {
  std::map<std::uint32_t, DbcMessage> messages;
  std::map<std::pair<std::uint32_t, std::string>, std::map<unsigned, std::string>> values;
  std::set<std::uint32_t> message_comments;
  std::set<std::pair<std::uint32_t, std::string>> signal_comments;
  bool network_comment = false;
};

// Reads the subset of the DBC grammar plinth.dbc uses (one statement per line).
inline Dbc parse_dbc(const std::string& path) {
  Dbc dbc;
  std::ifstream in(path);
  EXPECT_TRUE(in) << "cannot open " << path;
  std::string line;
  std::uint32_t current = 0;
  bool in_symbols = false;  // the NS_ block: one keyword a line, up to a blank line
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string keyword;
    ls >> keyword;
    if (keyword == "NS_") {
      in_symbols = true;
      continue;
    }
    if (in_symbols) {
      in_symbols = !keyword.empty();
      continue;
    }
    if (keyword == "BO_") {
      std::string name, sender;
      unsigned dlc = 0;
      ls >> current >> name >> dlc >> sender;
      EXPECT_FALSE(ls.fail()) << line;
      EXPECT_EQ(name.back(), ':') << line;
      name.pop_back();
      EXPECT_EQ(dbc.messages.count(current), 0U) << "duplicate identifier: " << line;
      dbc.messages[current] = DbcMessage{name, dlc, {}};
    } else if (keyword == "SG_") {
      // SG_ Name : start|length@order sign (factor,offset) [min|max] "unit" receivers
      DbcSignal s;
      std::string colon, layout, scaling, range, unit;
      ls >> s.name >> colon >> layout >> scaling >> range >> unit;
      EXPECT_EQ(colon, ":") << line;
      char bar = 0, at = 0, lp = 0, comma = 0, rp = 0, lb = 0, rb = 0;
      std::istringstream(layout) >> s.start >> bar >> s.length >> at >> s.byte_order >> s.sign;
      EXPECT_TRUE(bar == '|' && at == '@') << line;
      std::istringstream(scaling) >> lp >> s.factor >> comma >> s.offset >> rp;
      EXPECT_TRUE(lp == '(' && comma == ',' && rp == ')') << line;
      std::istringstream(range) >> lb >> s.minimum >> bar >> s.maximum >> rb;
      EXPECT_TRUE(lb == '[' && bar == '|' && rb == ']') << line;
      EXPECT_TRUE(unit.size() >= 2 && unit.front() == '"' && unit.back() == '"') << line;
      s.unit = unit.substr(1, unit.size() - 2);
      dbc.messages[current].signals.push_back(s);
    } else if (keyword == "VAL_") {
      std::uint32_t id = 0;
      std::string signal, token;
      ls >> id >> signal;
      auto& table = dbc.values[{id, signal}];
      while (ls >> token && token != ";") {
        const auto value = static_cast<unsigned>(std::stoul(token));
        std::string quoted;
        ls >> quoted;
        table[value] = quoted.substr(1, quoted.size() - 2);
      }
      EXPECT_EQ(token, ";") << line;
    } else if (keyword == "CM_") {
      std::string what;
      ls >> what;
      if (what == "BO_") {
        std::uint32_t id = 0;
        ls >> id;
        dbc.message_comments.insert(id);
      } else if (what == "SG_") {
        std::uint32_t id = 0;
        std::string signal;
        ls >> id >> signal;
        dbc.signal_comments.insert({id, signal});
      } else if (!what.empty() && what.front() == '"') {
        dbc.network_comment = true;
      }
    }
  }
  return dbc;
}

inline const Dbc& plinth_dbc() {
  static const Dbc dbc = parse_dbc(std::string(PLINTH_SOURCE_DIR) + "/hal/can_codec/plinth.dbc");
  return dbc;
}

}  // namespace plinth::testing
