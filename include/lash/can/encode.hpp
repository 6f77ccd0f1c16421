#pragma once
/// @file encode.hpp
/// Building one frame from signal values given as text (lash can encode) and
/// printing decoded values exactly.
///
/// Semantics: a signal not given takes its GenSigStartValue (BA_ of the signal, else
/// the BA_DEF_DEF_ default; a raw value, as Vector tools define it), else raw 0. A
/// value is a number in physical units, an integer that is stored exactly as the raw
/// value when factor = 1 and offset = 0 (all 64 bits), or a VAL_ text. A value outside
/// the DBC's [min|max] that fits the bit field is encoded as given with a warning
/// (EncodeRequest::clamp clamps it instead); a value that does not fit the field is an
/// InputError. Multiplexed signals are written only when their multiplexors' values
/// select them. Not real-time safe (use MessageCodec on the sample path).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/frame.hpp"

namespace lash::can {

struct EncodeRequest {
  std::vector<std::pair<std::string, std::string>> values;  ///< signal name, value text
  bool clamp = false;  ///< clamp values outside [min|max] instead of warning
};

struct EncodeOutcome {
  Frame frame;
  std::vector<std::string> warnings;
};

/// Throws lash::InputError (field = the signal) naming `file` for an unknown signal,
/// a value that is no number/VAL_ text or does not fit its bit field, or a message
/// whose layout has errors.
EncodeOutcome encode_message(const dbc::Database& db, const dbc::Message& message, const EncodeRequest& request,
                             const std::string& file = "<dbc>");

/// The raw start value of a signal: its GenSigStartValue attribute, the attribute's
/// default, else 0 (masked to the signal's length).
std::uint64_t start_value(const dbc::Database& db, const dbc::Message& message, const dbc::Signal& signal);

/// A decoded value as text: the exact integer when the signal is an integer with
/// factor 1 and offset 0 (all 64 bits), else the shortest round-trip double.
std::string format_value(const SignalCodec& codec, std::uint64_t raw);

}  // namespace lash::can
