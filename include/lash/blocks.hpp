#pragma once
/// @file blocks.hpp
/// All discrete-time blocks of docs/method.md §A1. Each is a small value type with a
/// `noexcept`, allocation-free, O(1) `step()`; configuration is checked in the
/// constructor (std::invalid_argument).
#include "lash/blocks/backlash_inverse.hpp"
#include "lash/blocks/deadband.hpp"
#include "lash/blocks/deadzone_inverse.hpp"
#include "lash/blocks/deadzone.hpp"
#include "lash/blocks/delay.hpp"
#include "lash/blocks/difference.hpp"
#include "lash/blocks/first_order.hpp"
#include "lash/blocks/moving_average.hpp"
#include "lash/blocks/saturation.hpp"
#include "lash/blocks/side.hpp"
