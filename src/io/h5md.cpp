#include "io/h5md.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/observables.hpp"

#ifndef IBROD_VERSION
#define IBROD_VERSION "unknown"
#endif

namespace ibrod::io {
namespace {

// Units as H5MD readers know them (MDAnalysis, h5py users): ASCII, time in ns, lengths in Å.
constexpr const char* kTimeUnit = "ns";
constexpr const char* kLengthUnit = "Angstrom";

// The unit attribute of an observable's values, from its column name ("" none: dimensionless).
const char* observable_unit(const std::string& name) {
  if (name.size() > 3 && name.compare(name.size() - 3, 3, "_kT") == 0) return "kT";
  if (name.size() > 2 && name.compare(name.size() - 2, 2, "_A") == 0) return kLengthUnit;
  return nullptr;
}

// HDF5 prints its error stack to stderr by default; ibrod reports errors itself (hdf5_error).
// No atexit clean-up either: HDF5 1.10 crashes at exit closing a file whose flush failed (a full
// disk); every file ibrod opens is closed by its owner (Hid) anyway.
void quiet_hdf5() {
  static std::once_flag once;
  std::call_once(once, [] {
    H5dont_atexit();  // must precede every other HDF5 call
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  });
}

// The innermost useful message of HDF5's error stack; errno texts get ibrod's hints.
std::string hdf5_error() {
  std::vector<std::string> descs;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* data) -> herr_t {
        if (e->desc) static_cast<std::vector<std::string>*>(data)->push_back(e->desc);
        return 0;
      },
      &descs);
  H5Eclear2(H5E_DEFAULT);
  for (const std::string& d : descs) {
    const auto at = d.find("errno = ");
    if (at != std::string::npos) return io_error_text(std::atoi(d.c_str() + at + 8));
  }
  if (descs.empty()) return "unknown HDF5 error";
  return descs.back();
}

// An HDF5 identifier closed by the matching H5?close.
class Hid {
 public:
  Hid() = default;
  Hid(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Hid() { reset(); }
  Hid(Hid&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Hid& operator=(Hid&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

struct Context {
  std::string file;
  [[noreturn]] void fail(const std::string& what) const {
    throw RunError("trajectory " + file + ": cannot " + what + ": " + hdf5_error());
  }
  hid_t ok(hid_t id, const std::string& what) const {
    if (id < 0) fail(what);
    return id;
  }
  Hid group(hid_t parent, const char* name, bool create) const {
    const hid_t g = create ? H5Gcreate2(parent, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                           : H5Gopen2(parent, name, H5P_DEFAULT);
    return Hid(ok(g, std::string(create ? "create" : "open") + " group " + name), H5Gclose);
  }
  Hid dataset(hid_t parent, const char* name) const {
    return Hid(ok(H5Dopen2(parent, name, H5P_DEFAULT), std::string("open dataset ") + name),
               H5Dclose);
  }
};

Hid utf8_string_type() {
  const hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_UTF8);
  return Hid(t, H5Tclose);
}

void string_attribute(const Context& cx, hid_t obj, const char* name,
                      const std::vector<std::string>& values, bool scalar) {
  Hid type = utf8_string_type();
  const hsize_t dims[1] = {values.size()};
  Hid space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, dims, nullptr), H5Sclose);
  Hid a(cx.ok(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT),
              std::string("create attribute ") + name),
        H5Aclose);
  std::vector<const char*> ptrs;
  for (const auto& v : values) ptrs.push_back(v.c_str());
  if (H5Awrite(a, type, ptrs.data()) < 0) cx.fail(std::string("write attribute ") + name);
}

// A scalar string attribute ("" if absent or not a string).
std::string read_string_attribute(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return "";
  Hid a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (a < 0) return "";
  Hid type(H5Aget_type(a), H5Tclose);
  if (H5Tget_class(type) != H5T_STRING) return "";
  std::string out;
  if (H5Tis_variable_str(type) > 0) {
    Hid mem = utf8_string_type();
    char* p = nullptr;
    if (H5Aread(a, mem, &p) >= 0 && p) {
      out = p;
      H5free_memory(p);
    }
  } else {
    std::string buf(H5Tget_size(type), '\0');
    if (H5Aread(a, type, buf.data()) >= 0) out = buf.c_str();
  }
  return out;
}

void int_attribute(const Context& cx, hid_t obj, const char* name, const std::vector<int>& values,
                   bool scalar) {
  const hsize_t dims[1] = {values.size()};
  Hid space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, dims, nullptr), H5Sclose);
  Hid a(cx.ok(H5Acreate2(obj, name, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT),
              std::string("create attribute ") + name),
        H5Aclose);
  if (H5Awrite(a, H5T_NATIVE_INT, values.data()) < 0)
    cx.fail(std::string("write attribute ") + name);
}

// An extendible dataset of rank 1 (inner empty) or 1 + inner.size(), first axis unlimited.
Hid extendible(const Context& cx, hid_t parent, const char* name, hid_t type,
               const std::vector<hsize_t>& inner, hsize_t chunk0) {
  std::vector<hsize_t> dims{0}, maxdims{H5S_UNLIMITED}, chunk{chunk0};
  for (hsize_t d : inner) {
    dims.push_back(d);
    maxdims.push_back(d);
    chunk.push_back(d);
  }
  Hid space(H5Screate_simple(int(dims.size()), dims.data(), maxdims.data()), H5Sclose);
  Hid dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(dcpl, int(chunk.size()), chunk.data());
  return Hid(cx.ok(H5Dcreate2(parent, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT),
                   std::string("create dataset ") + name),
             H5Dclose);
}

hsize_t length(const Context& cx, hid_t dset) {
  Hid space(cx.ok(H5Dget_space(dset), "read a dataspace"), H5Sclose);
  std::array<hsize_t, 3> dims{};
  if (H5Sget_simple_extent_dims(space, dims.data(), nullptr) < 0) cx.fail("read a dataspace");
  return dims[0];
}

std::vector<hsize_t> shape(const Context& cx, hid_t dset) {
  Hid space(cx.ok(H5Dget_space(dset), "read a dataspace"), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) cx.fail("read a dataspace");
  std::vector<hsize_t> dims(std::size_t(rank), 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return dims;
}

// Appends one record (inner-shaped) along the first axis.
void append_record(const Context& cx, hid_t dset, hid_t memtype, const void* data,
                   const std::vector<hsize_t>& inner, const char* what) {
  const hsize_t t = length(cx, dset);
  std::vector<hsize_t> dims{t + 1}, start{t}, count{1};
  for (hsize_t d : inner) {
    dims.push_back(d);
    start.push_back(0);
    count.push_back(d);
  }
  if (H5Dset_extent(dset, dims.data()) < 0) cx.fail(std::string("extend ") + what);
  Hid fspace(cx.ok(H5Dget_space(dset), "read a dataspace"), H5Sclose);
  H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  Hid mspace(H5Screate_simple(int(count.size()), count.data(), nullptr), H5Sclose);
  if (H5Dwrite(dset, memtype, mspace, fspace, H5P_DEFAULT, data) < 0)
    cx.fail(std::string("write ") + what);
}

void set_length(const Context& cx, hid_t dset, hsize_t t) {
  std::vector<hsize_t> dims = shape(cx, dset);
  dims[0] = t;
  if (H5Dset_extent(dset, dims.data()) < 0) cx.fail("truncate a dataset");
}

std::vector<std::int64_t> read_steps(const Context& cx, hid_t dset) {
  std::vector<std::int64_t> s(length(cx, dset));
  if (!s.empty() && H5Dread(dset, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data()) < 0)
    cx.fail("read steps");
  return s;
}

constexpr hsize_t kChunk1 = 128;  // records per chunk of step, time and scalar value datasets
const char* const kElements[4] = {"position", "d1", "d2", "d3"};

// A time-dependent H5MD element: step, time, value.
struct Series {
  Hid group, step, time, value;
  std::vector<hsize_t> inner;  // shape of one value record
};

}  // namespace

struct H5mdWriter::Impl {
  Context cx;
  Hid file;
  std::array<Series, 4> rod;  // kElements
  Series box;                 // box/edges, one record per frame
  double box_A = 0;
  std::vector<Series> observables;  // observable_fields()
  std::vector<double> buf;          // one frame of one element, [n × 3]
  int n = 0;

  void flush() {
    if (H5Fflush(file, H5F_SCOPE_LOCAL) < 0) cx.fail("flush");
  }

  static Series make(const Context& cx, hid_t parent, const char* name, std::vector<hsize_t> inner,
                     const char* unit) {
    Series s;
    s.group = cx.group(parent, name, true);
    s.inner = inner;
    s.step = extendible(cx, s.group, "step", H5T_STD_I64LE, {}, kChunk1);
    s.time = extendible(cx, s.group, "time", H5T_IEEE_F64LE, {}, kChunk1);
    string_attribute(cx, s.time, "unit", {kTimeUnit}, true);
    s.value = extendible(cx, s.group, "value", H5T_IEEE_F64LE, inner, inner.empty() ? kChunk1 : 1);
    if (unit) string_attribute(cx, s.value, "unit", {unit}, true);
    return s;
  }

  static Series open(const Context& cx, hid_t parent, const char* name,
                     std::vector<hsize_t> inner) {
    Series s;
    s.group = cx.group(parent, name, false);
    s.inner = inner;
    s.step = cx.dataset(s.group, "step");
    s.time = cx.dataset(s.group, "time");
    s.value = cx.dataset(s.group, "value");
    if (read_string_attribute(s.time, "unit") != kTimeUnit)
      throw RunError("trajectory " + cx.file + ": /" + name + "/time is not in " + kTimeUnit +
                     " (written by an older ibrod)");
    std::vector<hsize_t> want{0};
    want.insert(want.end(), inner.begin(), inner.end());
    std::vector<hsize_t> got = shape(cx, s.value);
    if (got.size() != want.size() || !std::equal(got.begin() + 1, got.end(), want.begin() + 1))
      throw RunError("trajectory " + cx.file + ": /" + name +
                     "/value does not have the shape this run writes (another rod size?)");
    return s;
  }

  // Keeps the records with step <= last (steps increase); returns how many remain.
  static hsize_t truncate(const Context& cx, Series& s, std::int64_t last) {
    const std::vector<std::int64_t> steps = read_steps(cx, s.step);
    const hsize_t usable =
        std::min({hsize_t(steps.size()), length(cx, s.time), length(cx, s.value)});
    hsize_t keep = 0;
    while (keep < usable && steps[keep] <= last && (keep == 0 || steps[keep] > steps[keep - 1]))
      ++keep;
    set_length(cx, s.step, keep);
    set_length(cx, s.time, keep);
    set_length(cx, s.value, keep);
    return keep;
  }

  void append(Series& s, std::int64_t step, double time_us, const void* value) {
    const double time_ns = time_us * 1e3;
    append_record(cx, s.step, H5T_NATIVE_INT64, &step, {}, "step");
    append_record(cx, s.time, H5T_NATIVE_DOUBLE, &time_ns, {}, "time");
    append_record(cx, s.value, H5T_NATIVE_DOUBLE, value, s.inner, "value");
  }

  void set_config(const std::string& config_toml, bool create) {
    Hid type = utf8_string_type();
    const char* ptr = config_toml.c_str();
    if (create) {
      Hid params = cx.group(file, "parameters", true);
      Hid space(H5Screate(H5S_SCALAR), H5Sclose);
      Hid d(cx.ok(H5Dcreate2(params, "config_toml", type, space, H5P_DEFAULT, H5P_DEFAULT,
                             H5P_DEFAULT),
                  "create /parameters/config_toml"),
            H5Dclose);
      if (H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr) < 0)
        cx.fail("write /parameters/config_toml");
    } else {
      Hid d = cx.dataset(file, "parameters/config_toml");
      if (H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr) < 0)
        cx.fail("write /parameters/config_toml");
    }
  }
};

namespace {
// No file locking: a reader (h5py, the renderer) may open the file while the run writes it.
Hid file_access() {
  Hid fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_file_locking(fapl, false, true);
  H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18);
  return fapl;
}
}  // namespace

std::unique_ptr<H5mdWriter> H5mdWriter::create(const std::filesystem::path& path, int n,
                                               double box_A, const std::string& config_toml,
                                               const std::vector<int>& species) {
  quiet_hdf5();
  std::unique_ptr<H5mdWriter> w(new H5mdWriter);
  w->impl_ = std::make_unique<Impl>();
  Impl& m = *w->impl_;
  m.cx.file = path.string();
  m.n = n;
  m.buf.resize(3 * std::size_t(n));
  const Context& cx = m.cx;
  Hid fapl = file_access();
  // Small chunk B-tree nodes: ~55 chunked datasets, each with its own index, would otherwise
  // make a file of a few frames weigh ~300 kB.
  Hid fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_istore_k(fcpl, 4);
  m.file =
      Hid(cx.ok(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, fapl), "create the file"), H5Fclose);

  {
    Hid h5md = cx.group(m.file, "h5md", true);
    int_attribute(cx, h5md, "version", {1, 1}, false);
    Hid author = cx.group(h5md, "author", true);
    const char* user = std::getenv("USER");
    string_attribute(cx, author, "name", {user && *user ? user : "unknown"}, true);
    Hid creator = cx.group(h5md, "creator", true);
    string_attribute(cx, creator, "name", {"ibrod"}, true);
    string_attribute(cx, creator, "version", {IBROD_VERSION}, true);
  }
  {
    Hid particles = cx.group(m.file, "particles", true);
    Hid rod = cx.group(particles, "rod", true);
    Hid box = cx.group(rod, "box", true);
    int_attribute(cx, box, "dimension", {3}, true);
    string_attribute(cx, box, "boundary", {"periodic", "periodic", "periodic"}, false);
    // time-dependent (step, time, value [T, 3, 3]) although the box never changes: H5MD allows
    // a fixed dataset, but MDAnalysis's H5MD reader reads box/edges/value per frame, and as the
    // D × D matrix of the box vectors (H5MD allows a D-vector too, which it reads as no box)
    m.box = Impl::make(cx, box, "edges", {3, 3}, kLengthUnit);
    m.box_A = box_A;
    for (int e2 = 0; e2 < 4; ++e2)
      m.rod[e2] =
          Impl::make(cx, rod, kElements[e2], {hsize_t(n), 3}, e2 == 0 ? kLengthUnit : nullptr);
    if (!species.empty()) {
      // several rods: each point's rod, time-independent (H5MD: a plain dataset)
      const hsize_t dims[1] = {species.size()};
      Hid space(H5Screate_simple(1, dims, nullptr), H5Sclose);
      Hid d(cx.ok(H5Dcreate2(rod, "species", H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT,
                             H5P_DEFAULT),
                  "create dataset species"),
            H5Dclose);
      if (H5Dwrite(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, species.data()) < 0)
        cx.fail("write dataset species");
    }
    // /particles/trajectory: a soft link to /particles/rod, the one group name that
    // MDAnalysis's H5MD reader counts atoms in when it opens the file alone
    // (mda.Universe("trajectory.h5md"), H5MDReader.parse_n_atoms); its reader itself takes the
    // first group, rod
    if (H5Lcreate_soft("/particles/rod", particles, "trajectory", H5P_DEFAULT, H5P_DEFAULT) < 0)
      cx.fail("create the link /particles/trajectory");
  }
  {
    Hid obs = cx.group(m.file, "observables", true);
    for (const auto& f : observable_fields())
      m.observables.push_back(Impl::make(cx, obs, f.name, {}, observable_unit(f.name)));
  }
  m.set_config(config_toml, true);
  m.flush();
  return w;
}

std::unique_ptr<H5mdWriter> H5mdWriter::reopen(const std::filesystem::path& path, int n,
                                               double box_A, std::int64_t last_step,
                                               const std::string& config_toml) {
  quiet_hdf5();
  std::unique_ptr<H5mdWriter> w(new H5mdWriter);
  w->impl_ = std::make_unique<Impl>();
  Impl& m = *w->impl_;
  m.cx.file = path.string();
  m.n = n;
  m.buf.resize(3 * std::size_t(n));
  const Context& cx = m.cx;
  Hid fapl = file_access();
  m.file = Hid(cx.ok(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl), "open the file"), H5Fclose);
  {
    Hid rod = cx.group(m.file, "particles/rod", false);
    for (int e = 0; e < 4; ++e) {
      m.rod[e] = Impl::open(cx, rod, kElements[e], {hsize_t(n), 3});
      const hsize_t kept = Impl::truncate(cx, m.rod[e], last_step);
      if (e == 0) w->frames_ = std::int64_t(kept);
    }
    Hid box = cx.group(rod, "box", false);
    // the edges as this file holds them: [T, 3, 3], or [T, 3] in files written before
    const std::vector<hsize_t> edges = shape(cx, cx.dataset(box, "edges/value"));
    m.box = Impl::open(cx, box, "edges",
                       edges.size() == 2 ? std::vector<hsize_t>{3} : std::vector<hsize_t>{3, 3});
    Impl::truncate(cx, m.box, last_step);
    m.box_A = box_A;
  }
  {
    Hid obs = cx.group(m.file, "observables", false);
    for (const auto& f : observable_fields()) {
      m.observables.push_back(Impl::open(cx, obs, f.name, {}));
      Impl::truncate(cx, m.observables.back(), last_step);
    }
  }
  m.set_config(config_toml, false);
  m.flush();
  return w;
}

H5mdWriter::~H5mdWriter() = default;

void H5mdWriter::write_frame(std::int64_t step, double time_us, const rod::RodState& s) {
  Impl& m = *impl_;
  const int n = s.size();
  if (n != m.n) throw RunError("trajectory " + m.cx.file + ": the rod changed size");
  for (int e = 0; e < 4; ++e) {
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < 3; ++i)
        m.buf[3 * std::size_t(k) + i] = e == 0 ? s.X[k][i] : s.D[k](i, e - 1);
    m.append(m.rod[e], step, time_us, m.buf.data());
  }
  const double L = m.box_A;
  const double matrix[9] = {L, 0, 0, 0, L, 0, 0, 0, L}, vector[3] = {L, L, L};
  m.append(m.box, step, time_us, m.box.inner.size() == 2 ? matrix : vector);
  m.flush();
  ++frames_;
}

void H5mdWriter::write_observables(const sim::Observables& o) {
  Impl& m = *impl_;
  const auto& fields = observable_fields();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const double v = o.*fields[i].member;
    m.append(m.observables[i], o.step, o.time_us, &v);
  }
  m.flush();
}

H5mdSeries read_h5md_series(const std::filesystem::path& path, const std::string& element) {
  quiet_hdf5();
  Context cx{path.string()};
  Hid fapl = file_access();
  Hid file(cx.ok(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl), "open the file"), H5Fclose);
  Hid g = cx.group(file, ("particles/rod/" + element).c_str(), false);
  Hid step = cx.dataset(g, "step"), time = cx.dataset(g, "time"), value = cx.dataset(g, "value");
  H5mdSeries s;
  s.step = read_steps(cx, step);
  s.time_us.resize(length(cx, time));
  if (!s.time_us.empty() &&
      H5Dread(time, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.time_us.data()) < 0)
    cx.fail("read time");
  // ns since ibrod wrote H5MD units that MDAnalysis reads; µs before
  const std::string unit = read_string_attribute(time, "unit");
  if (unit == kTimeUnit)
    for (double& t : s.time_us) t *= 1e-3;
  else if (unit != "µs")
    throw RunError("trajectory " + cx.file + ": time unit '" + unit + "' (expected ns or µs)");
  const std::vector<hsize_t> dims = shape(cx, value);
  if (dims.size() != 3 || dims[2] != 3)
    throw RunError("trajectory " + cx.file + ": bad value shape");
  s.n = int(dims[1]);
  s.value.resize(dims[0] * dims[1] * dims[2]);
  if (!s.value.empty() &&
      H5Dread(value, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.value.data()) < 0)
    cx.fail("read value");
  return s;
}

}  // namespace ibrod::io
