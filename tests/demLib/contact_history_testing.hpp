#pragma once
// Test helpers for contact-history records (test_pair_state_memory, test_list_rebuild).
#include <gtest/gtest.h>

#include "demLib/contact_law.hpp"

namespace dem_testing {

// A history whose shear and rolling parts are distinct, recognisable functions of s and r.
inline dem::ContactHistory history(double s, double r) {
    dem::ContactHistory h;
    h.shear = dem::Vec3(s, 2 * s, 3 * s);
    h.rollingAngle = dem::Vec3(r, -r, 0.5 * r);
    return h;
}

inline void expectHistory(const dem::ContactHistory& h, const dem::ContactHistory& expected) {
    EXPECT_EQ(h.shear, expected.shear);
    EXPECT_EQ(h.rollingAngle, expected.rollingAngle);
}

}  // namespace dem_testing
