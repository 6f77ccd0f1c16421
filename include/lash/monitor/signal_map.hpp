#pragma once
/// @file signal_map.hpp
/// The monitor's view of a bus: two signal expressions (v and y), each `MSG.SIG` or the
/// difference `MSG.SIG-MSG.SIG` of two DBC signals in physical units, resolved once against a
/// DBC (long names and multiplexed signals as the DBC reader and codec give them), and the
/// checks every frame of a watched message passes before its values are used (DESIGN.md,
/// "Safety on the bus"): length (DLC = the DBC's size), range (the DBC's [min|max] when
/// min < max) and alive counters (a signal of the message whose name contains "counter" or
/// "alive", any case: +1 per frame modulo 2^length). Not real-time safe to build; decode() is
/// noexcept and allocation-free.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/frame.hpp"

namespace lash::monitor {

/// One term of an expression.
struct SignalRef {
  std::string message;
  std::string signal;
};

/// `MSG.SIG` or `MSG.SIG-MSG.SIG` (plus − minus).
struct SignalExpr {
  SignalRef plus;
  bool has_minus = false;
  SignalRef minus;
  std::string text;
};

/// Parses an expression; InputError naming `field` (e.g. "--v") on bad text.
SignalExpr parse_signal_expr(const std::string& text, const std::string& field);

/// What decode() made of one frame.
enum class FrameCheck : std::uint8_t {
  other,         ///< not a watched message (or a remote/error frame)
  ok,            ///< values taken
  bad_dlc,       ///< length differs from the DBC's size: skipped
  out_of_range,  ///< a watched signal outside the DBC's [min|max]: skipped
};

class SignalMap {
 public:
  /// Resolves both expressions. InputError naming `dbc_file` and the field ("--v"/"--y") for a
  /// message or signal the DBC lacks, or a message whose layout cannot be coded.
  SignalMap(const can::dbc::Database& db, const SignalExpr& v, const SignalExpr& y, const std::string& dbc_file);
  ~SignalMap();
  SignalMap(SignalMap&&) noexcept;
  SignalMap& operator=(SignalMap&&) noexcept;

  /// Checks and decodes one frame, updating the latest value of every term it carries.
  /// `is_y` is set when the frame is one of y's first term's message (a sample instant);
  /// `counter_jump` when an alive counter of the message did not advance by one.
  FrameCheck decode(const can::Frame& f, bool& is_y, bool& counter_jump) noexcept;

  /// Latest v and y (NaN until every term has been received once).
  double v() const noexcept;
  double y() const noexcept;
  /// Forgets the counters' last values (after a silence the first counter is not a jump).
  void forget_counters() noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lash::monitor
