#include "plinth/host/scene_toml.h"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "plinth/core/ensemble_design.h"
#include "plinth/core/name_table.h"
#include "plinth/host/input_error.h"
#include "plinth/host/text_file.h"
#include "plinth/host/toml_names.h"

namespace plinth::host {
namespace {

// Shortest text that reads back as `value` ("2000", "0.3", "nan", "-inf").
std::string format_number(double value) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  if (result.ec != std::errc{}) return "?";
  return std::string(buffer.data(), result.ptr);
}

std::string_view type_name(toml::node_type type) { return toml_type_name(type); }

std::string join(std::span<const std::string_view> words) {
  std::string out;
  for (std::string_view word : words) {
    if (!out.empty()) out += ", ";
    out += word;
  }
  return out;
}

// A number read from the file: its value, its full dotted key and its line (0: unknown).
struct Number {
  double value = 0.0;
  std::string key;
  std::uint32_t line = 0;
};

// Where the value the core checks under one of its field names came from in the file.
using KeyValues = std::vector<std::pair<std::string, double>>;

struct Provenance {
  std::string key;  // the file's dotted key (or table name)
  std::uint32_t line = 0;
  std::optional<double> file_value;  // as written in the file
  // Set when the core's value was computed from the file's (e.g. eccentricity from
  // eccentricity_ratio): the core's value, shown next to the file's.
  std::optional<double> core_value;
  // The other keys the core's value was computed from, with their values in the file: a
  // complaint about the value names every input that made it.
  KeyValues other_inputs;
};

// The keys of each table (check_keys below takes the same lists).
const std::map<std::string_view, std::vector<std::string_view>, std::less<>> kKnownKeys{
    {"block",
     {"half_width", "slenderness", "com_height", "eccentricity_ratio", "eccentricity", "density",
      "depth", "mass", "inertia"}},
    {"base", {"mass_ratio", "mass", "period", "stiffness", "damping_ratio", "damping"}},
    {"friction", {"static", "kinetic"}},
    {"base_stops", {"max_displacement", "restitution"}},
    {"support", {"clearance"}},
    {"sliding_stops", {"restitution"}},
};

// Defaults that do not depend on other keys: an uncertainty may be declared around them.
const std::map<std::string, double, std::less<>> kConstantDefaults{
    {"block.eccentricity_ratio", 0.0}, {"block.eccentricity", 0.0}, {"block.depth", 1.0}};

class Loader {
 public:
  explicit Loader(std::string origin) : origin_(std::move(origin)) {}

  // Parses `text`; a TOML syntax error names the line and column.
  toml::table parse(const std::string& text) const {
    try {
      return toml::parse(text, origin_);
    } catch (const toml::parse_error& error) {
      const toml::source_position where = error.source().begin;
      throw InputError(origin_ + ":" + std::to_string(where.line) + ":" +
                       std::to_string(where.column) +
                       ": TOML syntax error: " + std::string(error.description()));
    }
  }

  // The scene a document describes; its [uncertainty] table, if any, is another reader's.
  Scene load(const toml::table& doc) {
    SceneParams params;
    static constexpr std::array<std::string_view, 9> kTopLevel{
        "gravity", "block", "base", "friction", "base_stops", "support", "sliding_stops",
        "uncertainty", "fragility"};
    check_keys(doc, "", kTopLevel);
    if (std::optional<Number> g = number(doc, "", "gravity")) {
      params.gravity = g->value;
      record("gravity", *g);
    }
    const toml::table* block = table(doc, "block");
    if (block == nullptr) fail(0, "block", "required table missing");
    read_block(*block, params);
    if (const toml::table* base = table(doc, "base")) read_base(*base, params);
    if (const toml::table* friction = table(doc, "friction")) read_friction(*friction, params);
    if (const toml::table* stops = table(doc, "base_stops")) read_base_stops(*stops, params);
    if (const toml::table* support = table(doc, "support")) read_support(*support, params);
    if (const toml::table* stops = table(doc, "sliding_stops")) read_sliding_stops(*stops, params);

    Scene scene;
    if (const Error error = make_scene(params, scene); !error.ok()) report(error);
    return scene;
  }

  // The [fragility] table: the statue's lognormal collapse fragility in PGA.
  std::optional<LognormalFragility> read_fragility(const toml::table& doc) const {
    const toml::table* tbl = table(doc, "fragility");
    if (tbl == nullptr) return std::nullopt;
    static constexpr std::array<std::string_view, 2> kKeys{"median_g", "beta"};
    check_keys(*tbl, "fragility", kKeys);
    const Number median = required(*tbl, "fragility", "median_g");
    const Number beta = required(*tbl, "fragility", "beta");
    if (!std::isfinite(median.value) || median.value <= 0.0) {
      fail(median.line, median.key, "must be a PGA above 0 g (got " + format_number(median.value) + ")");
    }
    if (!std::isfinite(beta.value) || beta.value < 0.0) {
      fail(beta.line, beta.key, "must be a dispersion of 0 or more (got " + format_number(beta.value) + ")");
    }
    return LognormalFragility{static_cast<Real>(median.value), static_cast<Real>(beta.value)};
  }

  // The [uncertainty] table: sub-tables named as the scene's, each key as in its table with a
  // range [low, high] around the file's value (or the key's default).
  std::vector<UncertainKey> read_uncertainty(const toml::table& doc) const {
    std::vector<UncertainKey> out;
    const toml::table* unc = table(doc, "uncertainty");
    if (unc == nullptr) return out;
    static constexpr std::array<std::string_view, 6> kTables{
        "block", "base", "friction", "base_stops", "support", "sliding_stops"};
    check_keys(*unc, "uncertainty", kTables);
    for (auto&& [name, node] : *unc) {
      const std::string prefix = "uncertainty." + std::string(name.str());
      const toml::table* ranges = node.as_table();
      if (ranges == nullptr) {
        fail(node.source().begin.line, prefix,
             "expected a table, got " + std::string(type_name(node.type())));
      }
      const toml::table* scene_table = table(doc, name.str());
      if (scene_table == nullptr) {
        fail(node.source().begin.line, prefix,
             "the scene has no [" + std::string(name.str()) + "] table to be uncertain about");
      }
      for (auto&& [key, range] : *ranges) {
        out.push_back(read_range(*scene_table, name.str(), key.str(), range));
      }
    }
    // toml++ keeps a table's keys sorted: file order is line order.
    std::stable_sort(out.begin(), out.end(),
                     [](const UncertainKey& a, const UncertainKey& b) { return a.line < b.line; });
    if (out.size() > static_cast<std::size_t>(kMaxUncertainParameters)) {
      fail(unc->source().begin.line, "uncertainty",
           "declares " + std::to_string(out.size()) + " uncertain keys; at most " +
               std::to_string(kMaxUncertainParameters));
    }
    return out;
  }

 private:
  [[noreturn]] void fail(std::uint32_t line, std::string_view key, std::string_view what) const {
    std::string message = origin_;
    if (line > 0) message += ":" + std::to_string(line);
    message += ": ";
    message += key;
    message += ": ";
    message += what;
    throw InputError(message);
  }

  static std::string dotted(std::string_view prefix, std::string_view key) {
    std::string out(prefix);
    if (!out.empty()) out += '.';
    out += key;
    return out;
  }

  // Rejects every key of `tbl` not in `known`, naming it with its full dotted name.
  void check_keys(const toml::table& tbl, std::string_view prefix,
                  std::span<const std::string_view> known) const {
    for (auto&& [key, node] : tbl) {
      bool found = false;
      for (std::string_view k : known) found = found || k == key.str();
      if (found) continue;
      const std::string name = dotted(prefix, key.str());
      const char* kind = node.is_table() ? "unknown table" : "unknown key";
      const std::string where = prefix.empty() ? std::string("at the top level")
                                               : "in [" + std::string(prefix) + "]";
      fail(key.source().begin.line, name,
           std::string(kind) + " (allowed " + where + ": " + join(known) + ")");
    }
  }

  // The sub-table `name` of the document, nullptr when absent; anything else is a type error.
  const toml::table* table(const toml::table& doc, std::string_view name) const {
    const toml::node* node = doc.get(name);
    if (node == nullptr) return nullptr;
    if (const toml::table* tbl = node->as_table()) return tbl;
    fail(node->source().begin.line, name,
         "expected a table, got " + std::string(type_name(node->type())));
  }

  // The number under `key`, nullopt when absent. Integers are accepted; other types and
  // non-finite values are rejected.
  std::optional<Number> number(const toml::table& tbl, std::string_view prefix,
                               std::string_view key) const {
    const toml::node* node = tbl.get(key);
    if (node == nullptr) return std::nullopt;
    Number out;
    out.key = dotted(prefix, key);
    out.line = node->source().begin.line;
    if (const toml::value<std::int64_t>* i = node->as_integer()) {
      out.value = static_cast<double>(i->get());
    } else if (const toml::value<double>* f = node->as_floating_point()) {
      out.value = f->get();
    } else {
      fail(out.line, out.key, "expected a number, got " + std::string(type_name(node->type())));
    }
    if (!std::isfinite(out.value)) {
      fail(out.line, out.key, "must be a finite number (got " + format_number(out.value) + ")");
    }
    return out;
  }

  Number required(const toml::table& tbl, std::string_view prefix, std::string_view key) const {
    std::optional<Number> n = number(tbl, prefix, key);
    if (!n) fail(tbl.source().begin.line, dotted(prefix, key), "required key missing");
    return *n;
  }

  // At most one of the keys `a` and `b`; `first` tells which one was given.
  struct Choice {
    Number number;
    bool first = true;
  };
  std::optional<Choice> either(const toml::table& tbl, std::string_view prefix, std::string_view a,
                               std::string_view b, bool needed) const {
    std::optional<Number> na = number(tbl, prefix, a);
    std::optional<Number> nb = number(tbl, prefix, b);
    if (na && nb) {
      fail(std::max(na->line, nb->line), nb->key,
           "give either " + na->key + " or " + nb->key + ", not both");
    }
    if (na) return Choice{*na, true};
    if (nb) return Choice{*nb, false};
    if (needed) {
      fail(tbl.source().begin.line, dotted(prefix, a),
           "required key missing (give " + dotted(prefix, a) + " or " + dotted(prefix, b) + ")");
    }
    return std::nullopt;
  }

  // `core_field` holds the file's number as it is.
  void record(const std::string& core_field, const Number& n) {
    provenance_[core_field] = Provenance{n.key, n.line, n.value, std::nullopt, {}};
  }
  // `core_field` holds `core_value`, computed from the file's number and the core fields
  // `others` (named in a complaint by the keys that gave them).
  void record(const std::string& core_field, const Number& n, double core_value,
              std::initializer_list<std::string_view> others = {}) {
    if (n.key == core_field && others.size() == 0) {
      record(core_field, n);
      return;
    }
    Provenance p{n.key, n.line, n.value, std::nullopt, inputs_of(others)};
    if (n.key != core_field) p.core_value = core_value;
    provenance_[core_field] = std::move(p);
  }

  // The keys (and their values in the file) that gave the core fields `fields`, each once: a
  // field computed from other keys brings its own inputs.
  KeyValues inputs_of(std::initializer_list<std::string_view> fields) const {
    KeyValues out;
    const auto add = [&](const std::string& key, double value) {
      const bool seen = std::any_of(out.begin(), out.end(),
                                    [&](const auto& kv) { return kv.first == key; });
      if (!seen) out.emplace_back(key, value);
    };
    for (std::string_view field : fields) {
      const auto it = provenance_.find(field);
      if (it == provenance_.end()) continue;
      if (it->second.file_value) add(it->second.key, *it->second.file_value);
      for (const auto& [key, value] : it->second.other_inputs) add(key, value);
    }
    return out;
  }

  // "block.half_width = 0.3, block.slenderness = 3".
  static std::string text_of(const KeyValues& inputs) {
    std::string out;
    for (const auto& [key, value] : inputs) {
      if (!out.empty()) out += ", ";
      out += key + " = " + format_number(value);
    }
    return out;
  }

  void read_block(const toml::table& tbl, SceneParams& params) {
    check_keys(tbl, "block", kKnownKeys.at("block"));
    BlockParams& blk = params.block;

    const Number b = required(tbl, "block", "half_width");
    blk.half_width = b.value;
    record("block.half_width", b);

    const Choice height = *either(tbl, "block", "slenderness", "com_height", true);
    blk.com_height = height.first ? height.number.value * blk.half_width : height.number.value;
    record("block.com_height", height.number, blk.com_height,
           height.first ? std::initializer_list<std::string_view>{"block.half_width"}
                        : std::initializer_list<std::string_view>{});

    if (std::optional<Choice> ecc =
            either(tbl, "block", "eccentricity_ratio", "eccentricity", false)) {
      blk.eccentricity = ecc->first ? ecc->number.value * blk.half_width : ecc->number.value;
      record("block.eccentricity", ecc->number, blk.eccentricity, {"block.half_width"});
    }

    const Choice mass = *either(tbl, "block", "density", "mass", true);
    std::optional<Number> depth = number(tbl, "block", "depth");
    if (mass.first) {
      double d = 1.0;
      if (depth) {
        if (depth->value <= 0.0) {
          fail(depth->line, depth->key,
               "must be greater than zero (got " + format_number(depth->value) + ")");
        }
        d = depth->value;
        record("block.depth", *depth);
      }
      blk.mass = mass.number.value * (2.0 * blk.half_width) * (2.0 * blk.com_height) * d;
      record("block.mass", mass.number, blk.mass,
             {"block.half_width", "block.com_height", "block.depth"});
    } else {
      if (depth) {
        fail(depth->line, depth->key,
             "is used only with block.density; with block.mass it has no meaning");
      }
      blk.mass = mass.number.value;
      record("block.mass", mass.number, blk.mass);
    }

    if (std::optional<Number> inertia = number(tbl, "block", "inertia")) {
      blk.inertia = inertia->value;
      record("block.inertia", *inertia);
    } else {
      blk.inertia = homogeneous_rectangle_inertia(blk.mass, blk.half_width, blk.com_height);
      // Not in the file: a complaint about it names the keys it was made from.
      derived_["block.inertia"] =
          "not given: m (b^2 + h^2) / 3 = " + format_number(blk.inertia) + " from " +
          text_of(inputs_of({"block.mass", "block.half_width", "block.com_height"}));
    }
  }

  void read_base(const toml::table& tbl, SceneParams& params) {
    check_keys(tbl, "base", kKnownKeys.at("base"));
    params.has_base = true;
    BaseParams& base = params.base;
    const double m = params.block.mass;

    const Choice mass = *either(tbl, "base", "mass_ratio", "mass", true);
    base.mass = mass.first ? mass.number.value * m : mass.number.value;
    record("base.mass", mass.number, base.mass,
           mass.first ? std::initializer_list<std::string_view>{"block.mass"}
                      : std::initializer_list<std::string_view>{});

    const Choice period = *either(tbl, "base", "period", "stiffness", true);
    if (period.first) {
      base.period = period.number.value;
    } else {
      const double k = period.number.value;
      if (k <= 0.0) {
        fail(period.number.line, period.number.key,
             "must be greater than zero (got " + format_number(k) + ")");
      }
      base.period = 2.0 * std::numbers::pi * std::sqrt((m + base.mass) / k);
    }
    record("base.period", period.number, base.period,
           period.first ? std::initializer_list<std::string_view>{}
                        : std::initializer_list<std::string_view>{"block.mass", "base.mass"});

    const Choice damping = *either(tbl, "base", "damping_ratio", "damping", true);
    if (damping.first) {
      base.damping_ratio = damping.number.value;
    } else {
      const double omega = 2.0 * std::numbers::pi / base.period;
      base.damping_ratio = damping.number.value / (2.0 * (m + base.mass) * omega);
    }
    record("base.damping_ratio", damping.number, base.damping_ratio,
           damping.first
               ? std::initializer_list<std::string_view>{}
               : std::initializer_list<std::string_view>{"block.mass", "base.mass", "base.period"});
  }

  void read_friction(const toml::table& tbl, SceneParams& params) {
    check_keys(tbl, "friction", kKnownKeys.at("friction"));
    params.has_friction = true;
    const Number mu_s = required(tbl, "friction", "static");
    params.friction.static_coefficient = mu_s.value;
    record("friction.static", mu_s);
    if (std::optional<Number> mu_k = number(tbl, "friction", "kinetic")) {
      params.friction.kinetic_coefficient = mu_k->value;
      record("friction.kinetic", *mu_k);
    } else {
      params.friction.kinetic_coefficient = 0.8 * mu_s.value;
    }
  }

  void read_base_stops(const toml::table& tbl, SceneParams& params) {
    check_keys(tbl, "base_stops", kKnownKeys.at("base_stops"));
    params.has_base_stops = true;
    provenance_["base_stops"] = Provenance{"base_stops", tbl.source().begin.line, {}, {}, {}};
    const Number u_max = required(tbl, "base_stops", "max_displacement");
    params.base_stops.max_displacement = u_max.value;
    record("base_stops.max_displacement", u_max);
    const Number eta = required(tbl, "base_stops", "restitution");
    params.base_stops.restitution = eta.value;
    record("base_stops.restitution", eta);
  }

  void read_support(const toml::table& tbl, SceneParams& params) {
    check_keys(tbl, "support", kKnownKeys.at("support"));
    params.has_support = true;
    provenance_["support"] = Provenance{"support", tbl.source().begin.line, {}, {}, {}};
    const Number clearance = required(tbl, "support", "clearance");
    params.support.clearance = clearance.value;
    record("support.clearance", clearance);
  }

  void read_sliding_stops(const toml::table& tbl, SceneParams& params) {
    check_keys(tbl, "sliding_stops", kKnownKeys.at("sliding_stops"));
    params.has_sliding_stops = true;
    provenance_["sliding_stops"] = Provenance{"sliding_stops", tbl.source().begin.line, {}, {}, {}};
    const Number eta = required(tbl, "sliding_stops", "restitution");
    params.sliding_stops.restitution = eta.value;
    record("sliding_stops.restitution", eta);
  }

  // Throws the core's complaint, under the key the file used for the field at fault.
  [[noreturn]] void report(const Error& error) const {
    const std::string field = error.field;
    const auto it = provenance_.find(field);
    if (const auto derived = derived_.find(field);
        it == provenance_.end() && derived != derived_.end()) {
      fail(0, field, error.reason + std::string(" (") + derived->second + ")");
    }
    if (it == provenance_.end()) fail(0, field, error.reason);
    const Provenance& p = it->second;
    std::string what = error.reason;
    if (p.file_value) {
      what += " (got " + format_number(*p.file_value);
      if (p.core_value) what += ", giving " + field + " = " + format_number(*p.core_value);
      if (!p.other_inputs.empty()) what += ", with " + text_of(p.other_inputs);
      what += ")";
    }
    fail(p.line, p.key, what);
  }

  // One key's range: known in its table, given there (or with a constant default), and
  // [low, high] two finite numbers with low <= nominal <= high.
  UncertainKey read_range(const toml::table& scene_table, std::string_view table_name,
                          std::string_view key, const toml::node& range) const {
    const std::string name = "uncertainty." + std::string(table_name) + "." + std::string(key);
    const std::uint32_t line = range.source().begin.line;
    const auto known = kKnownKeys.find(table_name);
    bool is_known = false;
    for (std::string_view k : known->second) is_known = is_known || k == key;
    if (!is_known) {
      fail(line, name,
           "unknown key (allowed in [" + std::string(table_name) + "]: " + join(known->second) + ")");
    }
    UncertainKey u;
    u.table = std::string(table_name);
    u.key = std::string(key);
    u.line = line;
    if (std::optional<Number> given = number(scene_table, table_name, key)) {
      u.nominal = given->value;
    } else if (const auto d = kConstantDefaults.find(dotted(table_name, key));
               d != kConstantDefaults.end()) {
      u.nominal = d->second;
    } else {
      fail(line, name,
           "the scene does not give " + dotted(table_name, key) +
               " (give it in [" + std::string(table_name) + "], or declare the uncertainty of "
               "the key it gives)");
    }
    const toml::array* pair = range.as_array();
    if (pair == nullptr || pair->size() != 2 || !(*pair)[0].is_number() ||
        !(*pair)[1].is_number()) {
      fail(line, name, "expected a range [low, high] of two numbers");
    }
    u.low = (*pair)[0].value<double>().value_or(0.0);
    u.high = (*pair)[1].value<double>().value_or(0.0);
    if (!std::isfinite(u.low) || !std::isfinite(u.high)) {
      fail(line, name, "the range's ends must be finite numbers");
    }
    if (!(u.low <= u.nominal && u.nominal <= u.high)) {
      fail(line, name,
           "the range [" + format_number(u.low) + ", " + format_number(u.high) +
               "] must hold the scene's value " + format_number(u.nominal) + " (low <= value <= high)");
    }
    return u;
  }

  std::string origin_;
  std::map<std::string, Provenance, std::less<>> provenance_;
  // Core fields computed from several keys, none of them the field's own: how.
  std::map<std::string, std::string, std::less<>> derived_;
};

// The document with the uncertain keys set: key i at `value(i)`.
template <class ValueOf>
toml::table with_values(const toml::table& doc, const std::vector<UncertainKey>& keys,
                        ValueOf value) {
  toml::table copy = doc;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    toml::table* tbl = copy.get_as<toml::table>(keys[i].table);
    tbl->insert_or_assign(keys[i].key, value(i));
  }
  return copy;
}

std::string describe(const std::vector<UncertainKey>& keys, const std::vector<double>& values) {
  std::string out;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!out.empty()) out += ", ";
    out += keys[i].table + "." + keys[i].key + " = " + format_number(values[i]);
  }
  return out;
}

}  // namespace

Scene UncertainScene::statue(std::span<const double> u) const {
  std::vector<double> values(uncertain.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double x = i < u.size() ? std::clamp(u[i], 0.0, 1.0) : 0.5;
    values[i] = uncertain[i].low + x * (uncertain[i].high - uncertain[i].low);
  }
  return scene_at(values);
}

Scene UncertainScene::scene_at(const std::vector<double>& values) const {
  Loader loader(origin_);
  const toml::table doc =
      with_values(loader.parse(text_), uncertain, [&](std::size_t i) { return values[i]; });
  try {
    return loader.load(doc);
  } catch (const InputError& e) {
    std::string_view why = e.what();
    if (why.starts_with(origin_ + ":")) why.remove_prefix(origin_.size() + 1);
    throw InputError(origin_ + ": uncertainty: the statue with " + describe(uncertain, values) +
                     " is not a valid scene:" + std::string(why));
  }
}

UncertainScene load_uncertain_scene_text(const std::string& text, const std::string& origin) {
  UncertainScene out;
  Loader loader(origin);
  const toml::table doc = loader.parse(text);
  out.text_ = text;
  out.origin_ = origin;
  out.nominal = loader.load(doc);
  out.uncertain = loader.read_uncertainty(doc);
  out.fragility = loader.read_fragility(doc);
  const int d = static_cast<int>(out.uncertain.size());
  std::vector<DesignPoint> points(static_cast<std::size_t>(design_point_count(d)));
  points.resize(static_cast<std::size_t>(two_level_design(d, points)));
  if (d == 0) points.resize(1);  // no uncertainty: the nominal statue alone
  out.members.push_back(out.nominal);
  for (std::size_t p = 1; p < points.size(); ++p) {
    std::vector<double> values(out.uncertain.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const UncertainKey& k = out.uncertain[i];
      const double z = points[p][i];
      values[i] = z < 0.0 ? k.nominal + z * (k.nominal - k.low) : k.nominal + z * (k.high - k.nominal);
    }
    out.members.push_back(out.scene_at(values));
  }
  return out;
}

UncertainScene load_uncertain_scene_file(const std::string& path) {
  return load_uncertain_scene_text(read_text_file(path, kMaxSceneFileBytes, "scene file"), path);
}

Scene load_scene_text(const std::string& text, const std::string& origin) {
  return load_uncertain_scene_text(text, origin).nominal;
}

Scene load_scene_file(const std::string& path) { return load_uncertain_scene_file(path).nominal; }

}  // namespace plinth::host
