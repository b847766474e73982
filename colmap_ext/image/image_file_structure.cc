#include "colmap_ext/image/image_file_structure.h"

#include <cstdint>
#include <cstdio>
#include <cstring>

namespace colmap {
namespace {

const char kTruncatedJpeg[] =
    "truncated JPEG: the file ends before its end-of-image marker (an "
    "interrupted copy?)";

// Why the bytes of a file that starts like a JPEG are not a whole JPEG
// image, or "". Walks its segments by their lengths and the entropy-coded
// data of each scan up to the next marker, as a decoder does, without
// decoding: a file cut anywhere ends before the end-of-image marker, and
// bytes overwritten in the middle leave data where a marker must be, or a
// marker that does not exist.
std::string JpegStructureError(const std::string& d) {
  const auto byte = [&d](size_t i) { return static_cast<unsigned char>(d[i]); };
  const size_t n = d.size();
  size_t i = 2;  // after the start-of-image marker
  while (true) {
    if (i >= n) {
      return kTruncatedJpeg;
    }
    if (byte(i) != 0xFF) {
      return "corrupt JPEG: data where a marker must be (byte " +
             std::to_string(i) + ")";
    }
    while (i < n && byte(i) == 0xFF) {
      ++i;  // fill bytes
    }
    if (i >= n) {
      return kTruncatedJpeg;
    }
    const unsigned char code = byte(i++);
    if (code == 0xD9) {
      return "";  // end of image; what follows (a camera's trailer) is not ours
    }
    if (code < 0xC0 || code == 0xD8 || (code >= 0xD0 && code <= 0xD7)) {
      char hex[3];
      std::snprintf(hex, sizeof(hex), "%02X", code);
      return std::string("corrupt JPEG: marker 0x") + hex +
             " cannot be at byte " + std::to_string(i - 2);
    }
    if (i + 2 > n) {
      return kTruncatedJpeg;
    }
    const size_t length = (byte(i) << 8) | byte(i + 1);
    if (length < 2) {
      return "corrupt JPEG: a segment of length " + std::to_string(length);
    }
    i += length;
    if (i > n) {
      return kTruncatedJpeg;
    }
    if (code != 0xDA) {
      continue;
    }
    // A scan: entropy-coded data up to the next marker; 0xFF 0x00 is a
    // stuffed 0xFF, 0xFF 0xD0..0xD7 a restart marker.
    while (true) {
      const void* found = std::memchr(d.data() + i, 0xFF, n - i);
      if (found == nullptr) {
        return kTruncatedJpeg;
      }
      i = static_cast<const char*>(found) - d.data();
      if (i + 1 >= n) {
        return kTruncatedJpeg;
      }
      const unsigned char next = byte(i + 1);
      if (next == 0x00 || (next >= 0xD0 && next <= 0xD7)) {
        i += 2;
      } else if (next == 0xFF) {
        i += 1;
      } else {
        break;  // a marker
      }
    }
  }
}

// Why the bytes of a file that starts like a PNG are not a whole PNG, or "".
std::string PngStructureError(const std::string& d) {
  size_t i = 8;  // after the signature
  while (i + 8 <= d.size()) {
    const auto byte = [&d](size_t k) {
      return static_cast<uint32_t>(static_cast<unsigned char>(d[k]));
    };
    const uint64_t length =
        (byte(i) << 24) | (byte(i + 1) << 16) | (byte(i + 2) << 8) | byte(i + 3);
    if (d.compare(i + 4, 4, "IEND") == 0) {
      return "";
    }
    i += 12 + length;  // length, type, data, CRC
  }
  return "truncated PNG: the file ends before its last chunk (an "
         "interrupted copy?)";
}

}  // namespace

std::string ImageBytesError(const std::string& data) {
  if (data.size() >= 3 && data.compare(0, 3, "\xFF\xD8\xFF") == 0) {
    return JpegStructureError(data);
  }
  if (data.size() >= 8 && data.compare(0, 8, "\x89PNG\r\n\x1A\n") == 0) {
    return PngStructureError(data);
  }
  return "";
}

}  // namespace colmap
