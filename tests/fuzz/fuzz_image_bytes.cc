// libFuzzer target: the structure walk of JPEG and PNG files that feature
// extraction runs before decoding an image (colmap_ext/image/).
#include "colmap_ext/image/image_file_structure.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  colmap::ImageBytesError(bytes);
  // Both signatures in front of the same bytes, so that every input is
  // walked as a JPEG and as a PNG.
  colmap::ImageBytesError("\xFF\xD8\xFF" + bytes);
  colmap::ImageBytesError(std::string("\x89PNG\r\n\x1A\n", 8) + bytes);
  return 0;
}
