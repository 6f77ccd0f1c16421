#pragma once
/// @file step_metrics.hpp
/// Moved to the metrics module (lash/metrics/step_response.hpp); kept so existing includes work.
#include "lash/metrics/step_response.hpp"
