/// libFuzzer target: the checkpoint reader (`read_checkpoint`, what `--resume` reads). Any
/// exception other than InputError, any sanitizer report, any hang is a bug: a damaged or
/// hostile checkpoint must become one clear InputError, and reading it must never take more
/// memory than its own size says.
///
/// The first byte picks how the rest is used:
///   even  the whole file, as is (the magic, the declared sizes, the checksum: all fuzzed);
///   odd   the body of a checkpoint: a real header (write_checkpoint's magic and fingerprint),
///         then the fuzzed bytes, then their valid checksum, so that inputs reach the checks
///         behind the checksum (film size, pixel sums, auxiliary sums, trailing data).
///
/// Run: scripts/fuzz.sh (short, CI) or, for a long run,
///   build-asan/checkpoint_fuzz -max_total_time=3600 fuzz/corpus/checkpoint

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "amalgam/io/checkpoint.h"
#include "fuzz_util.h"

namespace {

constexpr char kFingerprint[] = "fuzz";

/// The bytes write_checkpoint puts before the film: the magic and the fingerprint (its length,
/// then its text), taken from a real checkpoint so that the target follows the format.
const std::string& header() {
  static const std::string h = [] {
    amalgam::FilmState st;
    st.width = st.height = 1;
    st.sum.resize(1);
    st.tests.resize(1);
    st.aov.resize(1);
    const std::uint8_t none = 0;
    amalgam::fuzz::TempFile f("checkpoint-header", ".ckpt", &none, 0);
    amalgam::write_checkpoint(f.path(), kFingerprint, st);
    std::ifstream in(f.path(), std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    const std::size_t end = bytes.find(kFingerprint) + std::strlen(kFingerprint);
    return bytes.substr(0, end);
  }();
  return h;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace amalgam;
  if (size == 0) return 0;
  std::string file;
  if (data[0] % 2 == 0) {
    file.assign(reinterpret_cast<const char*>(data + 1), size - 1);
  } else {
    file = header();
    file.append(reinterpret_cast<const char*>(data + 1), size - 1);
    const std::uint64_t sum = checkpoint_checksum(file);
    file.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  }
  fuzz::TempFile f("checkpoint", ".ckpt", reinterpret_cast<const std::uint8_t*>(file.data()),
                   file.size());
  try {
    (void)read_checkpoint(f.path(), kFingerprint);
  } catch (const InputError&) {
    // Refused with a message: fine.
  }
  return 0;
}
