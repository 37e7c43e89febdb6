#include "candela/render/checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "candela/base/error.h"

namespace candela {
namespace {

constexpr char kMagic[8] = {'C', 'N', 'D', 'L', 'C', 'K', 'P', 'T'};
constexpr uint32_t kVersion = 3;
constexpr size_t kHeaderSize = 8 + 4 + 8 + 8;
constexpr size_t kPixelSize = 7 * 8 + 8;
constexpr size_t kHalfSize = 4 * 8 + 8;  // version 3: the first half's sums

struct Writer {
  std::string bytes;
  void raw(const void* p, size_t n) { bytes.append(static_cast<const char*>(p), n); }
  template <typename T>
  void put(T v) {
    raw(&v, sizeof v);
  }
  void str(const std::string& s) {
    put(uint32_t(s.size()));
    raw(s.data(), s.size());
  }
};

struct Reader {
  const char* p;
  const char* end;
  std::string file;
  void raw(void* out, size_t n) {
    if (size_t(end - p) < n) throw FileContentError("checkpoint '" + file + "': corrupt (payload too short)");
    std::memcpy(out, p, n);
    p += n;
  }
  template <typename T>
  T get() {
    T v;
    raw(&v, sizeof v);
    return v;
  }
  std::string str() {
    uint32_t n = get<uint32_t>();
    if (size_t(end - p) < n) throw FileContentError("checkpoint '" + file + "': corrupt (payload too short)");
    std::string s(p, n);
    p += n;
    return s;
  }
};

// A checkpoint that cannot be read (FileContentError) or written (OutputError), named in the message.
template <typename Error>
[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw Error("checkpoint '" + file.string() + "': " + what);
}
[[noreturn]] void fail_read(const std::filesystem::path& file, const std::string& what) { fail<FileContentError>(file, what); }
[[noreturn]] void fail_write(const std::filesystem::path& file, const std::string& what) { fail<OutputError>(file, what); }

}  // namespace

uint64_t fnv1a64(const void* data, size_t size, uint64_t hash) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= b[i];
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

std::string RenderFingerprint::difference(const RenderFingerprint& now) const {
  std::string out;
  if (scene_hash != now.scene_hash) out = "scene file differs";
  std::string settings_diff;
  auto find = [](const auto& list, const std::string& key) -> const std::string* {
    for (const auto& [k, v] : list)
      if (k == key) return &v;
    return nullptr;
  };
  for (const auto& [key, value] : settings) {
    const std::string* other = find(now.settings, key);
    std::string other_value = other ? *other : "(unset)";
    if (other_value != value)
      settings_diff += (settings_diff.empty() ? "" : ", ") + key + " " + value + " vs " + other_value;
  }
  for (const auto& [key, value] : now.settings)
    if (!find(settings, key)) settings_diff += (settings_diff.empty() ? "" : ", ") + key + " (unset) vs " + value;
  if (!settings_diff.empty()) out += (out.empty() ? "" : "; ") + std::string("settings differ: ") + settings_diff;
  return out;
}

void write_checkpoint(const std::filesystem::path& file, const Checkpoint& cp) {
  if (cp.pixels.size() != size_t(cp.width) * size_t(cp.height))
    fail<InternalError>(file, "pixel count does not match the size");
  Writer payload;
  payload.put(cp.fingerprint.scene_hash);
  payload.put(uint32_t(cp.fingerprint.settings.size()));
  for (const auto& [k, v] : cp.fingerprint.settings) {
    payload.str(k);
    payload.str(v);
  }
  payload.put(int32_t(cp.width));
  payload.put(int32_t(cp.height));
  payload.put(cp.non_finite_samples);
  payload.bytes.reserve(payload.bytes.size() + cp.pixels.size() * kPixelSize);
  for (const PixelSums& px : cp.pixels) {
    payload.raw(px.weighted, sizeof px.weighted);
    payload.raw(px.weighted_sq, sizeof px.weighted_sq);
    payload.put(px.weight);
    payload.put(px.count);
    payload.raw(px.half_weighted, sizeof px.half_weighted);
    payload.put(px.half_weight);
    payload.put(px.half_count);
  }
  for (const auto* splats : {&cp.splats, &cp.half_splats}) {
    if (!splats->empty() && splats->size() != cp.pixels.size() * 3)
      fail<InternalError>(file, "splat count does not match the size");
    payload.put(uint64_t(splats->size()));
    for (int64_t v : *splats) payload.put(v);
  }
  Writer header;
  header.raw(kMagic, sizeof kMagic);
  header.put(kVersion);
  header.put(uint64_t(payload.bytes.size()));
  header.put(fnv1a64(payload.bytes.data(), payload.bytes.size()));

  // Temporary file beside the target, fsynced, renamed over it, directory fsynced.
  std::filesystem::path dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::filesystem::path tmp = file;
  tmp += ".tmp." + std::to_string(getpid());
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail_write(file, std::string("cannot create '") + tmp.string() + "': " + std::strerror(errno));
  auto write_all = [&](const std::string& bytes) {
    const char* p = bytes.data();
    size_t left = bytes.size();
    while (left > 0) {
      ssize_t n = ::write(fd, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      p += n;
      left -= size_t(n);
    }
    return true;
  };
  bool ok = write_all(header.bytes) && write_all(payload.bytes) && ::fsync(fd) == 0;
  int err = errno;
  if (::close(fd) != 0 && ok) {
    ok = false;
    err = errno;
  }
  if (!ok || ::rename(tmp.c_str(), file.c_str()) != 0) {
    if (ok) err = errno;
    ::unlink(tmp.c_str());
    fail_write(file, std::string("cannot write: ") + std::strerror(err));
  }
  int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

std::string read_checkpoint_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail_read(file, "cannot open");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

Checkpoint read_checkpoint(const std::filesystem::path& file) { return parse_checkpoint(read_checkpoint_bytes(file), file); }

Checkpoint parse_checkpoint(std::string_view bytes, const std::filesystem::path& file) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    fail_read(file, "not a candela checkpoint (bad magic header)");
  if (bytes.size() < kHeaderSize) fail_read(file, "truncated (header incomplete)");
  Reader header{bytes.data() + sizeof kMagic, bytes.data() + kHeaderSize, file.string()};
  uint32_t version = header.get<uint32_t>();
  if (version > kVersion || version == 0)
    fail_read(file, "unsupported version " + std::to_string(version) + " (this candela reads version " +
                   std::to_string(kVersion) + ")");
  uint64_t size = header.get<uint64_t>(), hash = header.get<uint64_t>();
  if (bytes.size() - kHeaderSize < size)
    fail_read(file, "truncated (" + std::to_string(bytes.size()) + " bytes, expected " + std::to_string(kHeaderSize + size) + ")");
  if (bytes.size() - kHeaderSize > size) fail_read(file, "corrupt (trailing bytes after the payload)");
  if (fnv1a64(bytes.data() + kHeaderSize, size) != hash) fail_read(file, "corrupt (checksum mismatch)");

  Reader r{bytes.data() + kHeaderSize, bytes.data() + bytes.size(), file.string()};
  Checkpoint cp;
  cp.fingerprint.scene_hash = r.get<uint64_t>();
  uint32_t n = r.get<uint32_t>();
  for (uint32_t i = 0; i < n; ++i) {
    std::string k = r.str();
    std::string v = r.str();
    cp.fingerprint.settings.emplace_back(std::move(k), std::move(v));
  }
  cp.width = r.get<int32_t>();
  cp.height = r.get<int32_t>();
  cp.non_finite_samples = r.get<uint64_t>();
  const uint64_t pixel_size = kPixelSize + (version >= 3 ? kHalfSize : 0);
  const uint64_t left = uint64_t(r.end - r.p);
  // The pixel count is checked against the bytes left by division first: the product of the
  // size's bytes can pass 2^64 (2^30 x 2^30 x 64 wraps to 0, the size of an empty version 1 film).
  const bool fits = cp.width >= 0 && cp.height >= 0 &&
                    (cp.height == 0 || uint64_t(cp.width) <= left / pixel_size / uint64_t(cp.height));
  const uint64_t pixel_bytes = fits ? uint64_t(cp.width) * uint64_t(cp.height) * pixel_size : 0;
  if (!fits || (version == 1 ? left != pixel_bytes : left < pixel_bytes + 8))
    fail_read(file, "corrupt (pixel data does not match the size)");
  cp.pixels.resize(size_t(cp.width) * size_t(cp.height));
  for (PixelSums& px : cp.pixels) {
    r.raw(px.weighted, sizeof px.weighted);
    r.raw(px.weighted_sq, sizeof px.weighted_sq);
    px.weight = r.get<double>();
    px.count = r.get<uint64_t>();
    if (version >= 3) {
      r.raw(px.half_weighted, sizeof px.half_weighted);
      px.half_weight = r.get<double>();
      px.half_count = r.get<uint64_t>();
    }
  }
  // Version 2 has the splats, version 3 also the first half's.
  for (auto* splats : {&cp.splats, &cp.half_splats}) {
    if (version < 2 || (version < 3 && splats == &cp.half_splats)) break;
    const bool last = version < 3 || splats == &cp.half_splats;
    uint64_t count = r.get<uint64_t>();
    if ((count != 0 && count != uint64_t(cp.pixels.size()) * 3) || uint64_t(r.end - r.p) < count * 8 ||
        (last && uint64_t(r.end - r.p) != count * 8))
      fail_read(file, "corrupt (splat data does not match the size)");
    splats->resize(size_t(count));
    for (int64_t& v : *splats) v = r.get<int64_t>();
  }
  return cp;
}

}  // namespace candela
