/// libFuzzer target: the texture decoders (`decode_image`: libpng, libjpeg, OpenEXR and
/// stb_image, as the import helper runs them). A hostile image must be decoded or refused with
/// a reason, never crash, read out of bounds, leak or hang, and a decoded image must hold
/// exactly width x height texels within the limits it was given.
///
/// Run: scripts/fuzz.sh (short, CI) or, for a long run,
///   build-asan/image_fuzz -max_total_time=3600 fuzz/corpus/image

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "amalgam/io/image_decode.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Small limits: a header claiming a large image is refused as the helper would refuse a huge
  // one, and decoding stays fast under the sanitizers (at 2^20 texels: 17 inputs/s, 1.6 GB).
  constexpr std::uint64_t kMaxTexels = std::uint64_t{1} << 16;
  constexpr std::uint32_t kMaxSide = 1024;
  amalgam::Texture t;
  std::string why;
  if (amalgam::decode_image(data, size, kMaxTexels, kMaxSide, t, why)) {
    const std::uint64_t n = std::uint64_t{t.width} * t.height;
    if (t.width == 0 || t.height == 0 || t.width > kMaxSide || t.height > kMaxSide ||
        n > kMaxTexels || t.texels.size() != 3 * n)
      std::abort();
  } else if (why.empty()) {
    std::abort();  // every refusal says why
  }
  return 0;
}
