// src/util/Base64.h against RFC 4648's test vectors (section 10) and a
// round trip of every byte value; text that is not base64 is refused.
#include <gtest/gtest.h>

#include "src/util/Base64.h"

namespace vdbdag {

TEST(Base64, Rfc4648Vectors) {
    const std::pair<const char*, const char*> vectors[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},        {"foo", "Zm9v"},
                                                           {"foob", "Zm9vYg=="}, {"fooba", "Zm9vYmE="}, {"foobar", "Zm9vYmFy"}};
    for (const auto& [plain, coded] : vectors) {
        EXPECT_EQ(encodeBase64(plain), coded) << plain;
        EXPECT_EQ(decodeBase64(coded), std::string(plain)) << coded;
    }
}

TEST(Base64, EveryByteRoundTrips) {
    std::string all;
    for (int i = 0; i < 256; ++i) all += char(i);
    for (size_t n = 0; n <= all.size(); n += 37) EXPECT_EQ(decodeBase64(encodeBase64(all.substr(0, n))), all.substr(0, n)) << n;
}

TEST(Base64, RefusesWhatIsNotBase64) {
    for (const char* bad : {"Zg=", "Z===", "Zm9v!", "Zg==Zg==", "=Zg=", "Zm=v"}) EXPECT_FALSE(decodeBase64(bad).has_value()) << bad;
}

} // namespace vdbdag
