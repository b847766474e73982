// Whether the bytes of an image file can be a whole image, without decoding.
// Standard library only (fuzzed on its own: tests/fuzz/).
#pragma once

#include <string>

namespace colmap {

// Why the bytes of a JPEG or PNG file (recognised by their signature) are
// not a whole image, or "" (also for other formats, which are left to the
// decoder). A JPEG's segments are walked by their lengths and each scan's
// entropy-coded data up to the next marker, as a decoder does: a file cut
// anywhere ends before the end-of-image marker, and bytes overwritten in the
// middle leave data where a marker must be, or a marker that does not exist.
// A PNG's chunks are walked up to IEND.
std::string ImageBytesError(const std::string& data);

}  // namespace colmap
