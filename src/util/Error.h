// vdbdag::Error is part of the public reader API: include/vdbdag/Error.h.
#pragma once
#include "include/vdbdag/Error.h"
