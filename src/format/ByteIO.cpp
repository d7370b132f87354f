// ByteIO.h copies values to and from bytes with memcpy, so the .ssvdag format
// is little-endian only because the host is. Refuse to build anywhere else
// rather than write files other machines would misread.
#include "src/format/ByteIO.h"

#include <bit>
#include <limits>

namespace vdbdag::format {

static_assert(std::endian::native == std::endian::little,
              "vdbdag's byte I/O (ByteIO.h) and the .ssvdag format assume a little-endian host; add byte swapping before porting");
static_assert(sizeof(float) == 4 && sizeof(double) == 8 && std::numeric_limits<float>::is_iec559 && std::numeric_limits<double>::is_iec559,
              "the .ssvdag format stores IEEE-754 binary32/binary64 values bit for bit");

} // namespace vdbdag::format
