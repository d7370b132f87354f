// The groups of selftest cases, one file each (ValueCases.cpp,
// GeometryCases.cpp, ColourCases.cpp, NormalCases.cpp, RayCases.cpp); the
// registry (Selftest.cpp) concatenates them in this order.
#pragma once
#include <vector>

#include "src/selftest/Selftest.h"

namespace vdbdag::selftest {

void addValueCases(std::vector<SelftestCase>& cases);
void addGeometryCases(std::vector<SelftestCase>& cases);
void addColourCases(std::vector<SelftestCase>& cases);
void addNormalCases(std::vector<SelftestCase>& cases);
void addRayCases(std::vector<SelftestCase>& cases);

} // namespace vdbdag::selftest
