#include <gtest/gtest.h>
#include <string>
#include "demLib/version.hpp"

namespace dem { const char* libraryVersion(); }

TEST(Version, LibraryMatchesHeader) {
    EXPECT_EQ(std::string(dem::libraryVersion()), std::string(dem::versionString));
    EXPECT_EQ(dem::versionMajor, 0);
}
