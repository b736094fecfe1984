#include "io/checkpoint.hpp"

#include <array>
#include <bit>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/error.hpp"
#include "core/text_file.hpp"
#include "io/atomic_file.hpp"
#include "io/observables.hpp"
#include "io/observables_json.hpp"

namespace ibrod::io {

static_assert(std::endian::native == std::endian::little,
              "checkpoints are little-endian; add byte swapping for this host");

namespace {

constexpr char kMagic[8] = {'I', 'B', 'R', 'O', 'D', 'C', 'K', 'P'};
constexpr std::uint32_t kByteOrderMark = 0x01020304u;
constexpr std::size_t kHeaderBytes = 32;

struct Header {
  char magic[8];
  std::uint32_t version;
  std::uint32_t byte_order;
  std::uint64_t payload_bytes;
  std::uint32_t crc;
  std::uint32_t zero;
};
static_assert(sizeof(Header) == kHeaderBytes);

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr auto kCrcTable = make_crc_table();

sim::Observables observables_from(const nlohmann::json& j) {
  sim::Observables o;
  o.step = j.at("step").get<std::int64_t>();
  o.time_us = j.at("time_us").get<double>();
  for (const auto& f : observable_fields())
    o.*f.member = j.at(f.name).is_null() ? std::numeric_limits<double>::quiet_NaN()
                                         : j.at(f.name).get<double>();
  return o;
}

std::string meta_json(const CheckpointMeta& m) {
  nlohmann::ordered_json j;
  j["step"] = m.step;
  j["time_s"] = m.time_s;
  j["threads"] = m.threads;
  j["stop_reason"] = m.stop_reason;
  j["self_passage_warning"] = m.self_passage_warning;
  j["self_passage_step"] = m.self_passage_step;
  j["max_link_drift"] = m.max_link_drift;
  j["wall_s"] = m.wall_s;
  j["resumes"] = m.resumes;
  j["stability_tests"] = nlohmann::json::parse(m.stability_tests_json);
  j["implicit_next_dt_s"] = m.implicit_next_dt_s;
  j["implicit_accepted_in_a_row"] = m.implicit_accepted_in_a_row;
  if (!m.implicit_filter_X.empty())
    j["implicit_filter"] = {{"steps_since_refresh", m.implicit_filter_steps},
                            {"X", m.implicit_filter_X},
                            {"D", m.implicit_filter_D}};
  j["initial"] = observables_json(m.initial);
  j["config_toml"] = m.config_toml;
  return j.dump();  // doubles with 17 significant digits: they read back exactly
}

CheckpointMeta meta_from(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text);
  CheckpointMeta m;
  m.step = j.at("step").get<std::int64_t>();
  // checkpoints written before time was state have none: −1, the driver uses step × Δt
  m.time_s = j.contains("time_s") ? j.at("time_s").get<double>() : -1.0;
  m.threads = j.at("threads").get<int>();
  m.stop_reason = j.at("stop_reason").get<std::string>();
  m.self_passage_warning = j.at("self_passage_warning").get<bool>();
  m.self_passage_step = j.at("self_passage_step").get<std::int64_t>();
  m.max_link_drift = j.at("max_link_drift").get<double>();
  m.wall_s = j.at("wall_s").get<double>();
  m.resumes = j.at("resumes").get<std::int64_t>();
  m.stability_tests_json = j.contains("stability_tests") ? j.at("stability_tests").dump() : "[]";
  // absent in checkpoints from before the implicit scheme
  if (j.contains("implicit_next_dt_s")) {
    m.implicit_next_dt_s = j.at("implicit_next_dt_s").get<double>();
    m.implicit_accepted_in_a_row = j.at("implicit_accepted_in_a_row").get<int>();
  }
  // absent without thermal noise and in checkpoints from before it was kept
  if (j.contains("implicit_filter")) {
    const auto& f = j.at("implicit_filter");
    m.implicit_filter_steps = f.at("steps_since_refresh").get<std::int64_t>();
    m.implicit_filter_X = f.at("X").get<std::vector<double>>();
    m.implicit_filter_D = f.at("D").get<std::vector<double>>();
    if (m.implicit_filter_X.size() % 3 != 0 ||
        m.implicit_filter_D.size() != 3 * m.implicit_filter_X.size() ||
        m.implicit_filter_steps < 1)
      throw std::invalid_argument("its implicit_filter's X, D and steps_since_refresh do not fit");
  }
  m.initial = observables_from(j.at("initial"));
  m.config_toml = j.at("config_toml").get<std::string>();
  return m;
}

// Writes payload pieces and keeps the running CRC and size.
struct PayloadWriter {
  AtomicFile& f;
  std::uint32_t crc = 0;
  std::uint64_t bytes = 0;
  void put(const void* p, std::size_t n) {
    f.write(p, n);
    crc = crc32(p, n, crc);
    bytes += n;
  }
  template <class T>
  void put_value(T v) {
    put(&v, sizeof v);
  }
};

// Reads payload pieces, throwing "truncated" past the end.
struct PayloadReader {
  const char* p;
  std::size_t left;
  const std::string& name;
  void get(void* out, std::size_t n) {
    if (n > left)
      throw ConfigError("checkpoint " + name + " is inconsistent: its payload ends early");
    std::memcpy(out, p, n);
    p += n;
    left -= n;
  }
  template <class T>
  T get_value() {
    T v;
    get(&v, sizeof v);
    return v;
  }
};

}  // namespace

std::uint32_t crc32(const void* data, std::size_t bytes, std::uint32_t crc) {
  const auto* p = static_cast<const unsigned char*>(data);
  crc = ~crc;
  for (std::size_t i = 0; i < bytes; ++i) crc = kCrcTable[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

void write_checkpoint(const std::filesystem::path& path, const CheckpointMeta& meta,
                      const rod::RodState& rod, int grid_n, std::array<const double*, 3> u) {
  AtomicFile f(path);
  Header h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.version = kCheckpointVersion;
  h.byte_order = kByteOrderMark;
  f.write(&h, sizeof h);  // placeholder: size and CRC are known at the end

  PayloadWriter w{f};
  const std::string json = meta_json(meta);
  w.put_value<std::uint64_t>(json.size());
  w.put(json.data(), json.size());
  const std::int64_t n = rod.size();
  w.put_value<std::int64_t>(n);
  for (const Vec3& x : rod.X) w.put(x.data(), 3 * sizeof(double));
  for (const Mat3& d : rod.D) w.put(d.data(), 9 * sizeof(double));  // column-major: D¹, D², D³
  w.put_value<std::int64_t>(grid_n);
  const std::size_t n3 = std::size_t(grid_n) * grid_n * grid_n;
  for (int c = 0; c < 3; ++c) w.put(u[c], n3 * sizeof(double));

  h.payload_bytes = w.bytes;
  h.crc = w.crc;
  f.write_at(0, &h, sizeof h);
  f.commit(/*durable=*/true);
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  const std::string name = path.string();
  if (const std::string why = unreadable_reason(path); !why.empty())
    throw ConfigError("checkpoint " + name + " cannot be read: " + why);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw ConfigError("checkpoint " + name + " cannot be read (missing or no permission)");
  const std::streamoff size = in.tellg();
  in.seekg(0);
  std::vector<char> buf(std::size_t(std::max<std::streamoff>(size, 0)));
  if (!in.read(buf.data(), std::streamsize(buf.size())))
    throw ConfigError("checkpoint " + name + " cannot be read");

  Header h{};
  if (buf.size() < kHeaderBytes || std::memcmp(buf.data(), kMagic, sizeof kMagic) != 0) {
    if (buf.size() >= sizeof kMagic && std::memcmp(buf.data(), kMagic, sizeof kMagic) == 0)
      throw ConfigError("checkpoint " + name + " is truncated: " + std::to_string(buf.size()) +
                        " bytes, shorter than its header");
    throw ConfigError("checkpoint " + name + " is not an ibrod checkpoint (no IBRODCKP header)");
  }
  std::memcpy(&h, buf.data(), sizeof h);
  if (h.byte_order != kByteOrderMark)
    throw ConfigError("checkpoint " + name + " was written on a machine of another byte order");
  if (h.version != kCheckpointVersion)
    throw ConfigError("checkpoint " + name + " has format version " + std::to_string(h.version) +
                      "; this ibrod reads version " + std::to_string(kCheckpointVersion));
  const std::uint64_t have = buf.size() - kHeaderBytes;
  if (have < h.payload_bytes)
    throw ConfigError("checkpoint " + name + " is truncated: " + std::to_string(buf.size()) +
                      " bytes, the header announces " +
                      std::to_string(h.payload_bytes + kHeaderBytes));
  if (have > h.payload_bytes)
    throw ConfigError("checkpoint " + name + " is corrupt: " + std::to_string(buf.size()) +
                      " bytes, the header announces " +
                      std::to_string(h.payload_bytes + kHeaderBytes));
  const char* payload = buf.data() + kHeaderBytes;
  const std::uint32_t crc = crc32(payload, h.payload_bytes);
  if (crc != h.crc) {
    char msg[160];
    std::snprintf(msg, sizeof msg,
                  " is corrupt: CRC-32 of the payload is %08x, the header says %08x", crc, h.crc);
    throw ConfigError("checkpoint " + name + msg);
  }

  // The checksum holds: from here on a failure means a writer bug, still reported, never UB.
  PayloadReader r{payload, std::size_t(h.payload_bytes), name};
  Checkpoint ck;
  const auto json_bytes = r.get_value<std::uint64_t>();
  if (json_bytes > r.left)
    throw ConfigError("checkpoint " + name + " is inconsistent: bad meta size");
  std::string json(json_bytes, '\0');
  r.get(json.data(), json.size());
  try {
    ck.meta = meta_from(json);
  } catch (const nlohmann::json::exception& e) {
    throw ConfigError("checkpoint " + name + " has unreadable metadata: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw ConfigError("checkpoint " + name + " is inconsistent: " + e.what());
  }
  const auto n = r.get_value<std::int64_t>();
  if (n < 0 || std::uint64_t(n) > r.left / (12 * sizeof(double)))
    throw ConfigError("checkpoint " + name + " is inconsistent: bad rod size " + std::to_string(n));
  ck.rod.X.resize(std::size_t(n));
  ck.rod.D.resize(std::size_t(n));
  for (Vec3& x : ck.rod.X) r.get(x.data(), 3 * sizeof(double));
  for (Mat3& d : ck.rod.D) r.get(d.data(), 9 * sizeof(double));
  if (!ck.meta.implicit_filter_X.empty() && ck.meta.implicit_filter_X.size() != 3 * std::size_t(n))
    throw ConfigError("checkpoint " + name + " is inconsistent: its implicit_filter has " +
                      std::to_string(ck.meta.implicit_filter_X.size() / 3) + " points, the rods " +
                      std::to_string(n));
  const auto gn = r.get_value<std::int64_t>();
  if (gn < 1 || gn > 1 << 14)
    throw ConfigError("checkpoint " + name + " is inconsistent: bad grid size " +
                      std::to_string(gn));
  ck.grid_n = int(gn);
  const std::size_t values = 3 * std::size_t(gn) * std::size_t(gn) * std::size_t(gn);
  if (values * sizeof(double) != r.left)
    throw ConfigError("checkpoint " + name + " is inconsistent: the fluid block has " +
                      std::to_string(r.left) + " bytes, a " + std::to_string(gn) + "³ grid needs " +
                      std::to_string(values * sizeof(double)));
  ck.velocity.resize(values);
  r.get(ck.velocity.data(), values * sizeof(double));
  return ck;
}

void write_checkpoint(const std::filesystem::path& path, const CheckpointMeta& meta,
                      const sim::Snapshot& s, int grid_n) {
  const std::size_t n3 = std::size_t(grid_n) * std::size_t(grid_n) * std::size_t(grid_n);
  if (s.velocity.size() != 3 * n3)
    throw std::invalid_argument("write_checkpoint: the snapshot holds no whole velocity");
  const double* v = s.velocity.data();
  write_checkpoint(path, meta, s.rod, grid_n, {v, v + n3, v + 2 * n3});
}

void record_state(CheckpointMeta& meta, const sim::Snapshot& s) {
  meta.step = s.step;
  meta.time_s = s.time;
  meta.implicit_next_dt_s = s.implicit.next_dt > 0 ? s.implicit.next_dt : -1.0;
  meta.implicit_accepted_in_a_row = s.implicit.next_dt > 0 ? s.implicit.accepted_in_a_row : 0;
  meta.implicit_filter_steps = 0;
  meta.implicit_filter_X.clear();
  meta.implicit_filter_D.clear();
  if (s.implicit.next_dt > 0 && s.implicit.held) {
    const rod::RodState& q = s.implicit.held->at;
    meta.implicit_filter_steps = s.implicit.held->steps_since_refresh;
    for (const Vec3& x : q.X) meta.implicit_filter_X.insert(meta.implicit_filter_X.end(), x.data(), x.data() + 3);
    for (const Mat3& d : q.D) meta.implicit_filter_D.insert(meta.implicit_filter_D.end(), d.data(), d.data() + 9);
  }
}

sim::Snapshot snapshot_of(Checkpoint&& ck, double dt) {
  sim::Snapshot s;
  s.rod = std::move(ck.rod);
  s.velocity = std::move(ck.velocity);
  s.step = ck.meta.step;
  // checkpoints from before time was state: step × Δt of the run that wrote them
  s.time = ck.meta.time_s >= 0 ? ck.meta.time_s : double(ck.meta.step) * dt;
  s.implicit = {ck.meta.implicit_next_dt_s, ck.meta.implicit_accepted_in_a_row, std::nullopt};
  if (!ck.meta.implicit_filter_X.empty()) {
    integrate::ImplicitStepper::HeldFilter h;
    h.steps_since_refresh = long(ck.meta.implicit_filter_steps);
    const std::size_t n = ck.meta.implicit_filter_X.size() / 3;
    h.at.X.resize(n);
    h.at.D.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      std::copy_n(ck.meta.implicit_filter_X.data() + 3 * k, 3, h.at.X[k].data());
      std::copy_n(ck.meta.implicit_filter_D.data() + 9 * k, 9, h.at.D[k].data());
    }
    s.implicit.held = std::move(h);
  }
  return s;
}

}  // namespace ibrod::io
