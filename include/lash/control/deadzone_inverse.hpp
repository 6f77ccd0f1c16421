#pragma once
/// @file deadzone_inverse.hpp
/// The deadzone inverse lives in the blocks layer now (lash/blocks/deadzone_inverse.hpp);
/// this header stays for code that included it from control.
#include "lash/blocks/deadzone_inverse.hpp"
