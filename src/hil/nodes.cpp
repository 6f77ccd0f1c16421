#include "lash/hil/nodes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "lash/identify/verdict.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::hil {

namespace {

void validate(const E2EConfig& e, std::uint32_t counter_bits, const char* who) {
  const std::string w(who);
  if (e.max_counter_delta < 1 || e.max_counter_delta >= (1u << (counter_bits - 1)))
    throw std::invalid_argument(w + ": e2e.max_counter_delta must be in 1.." + std::to_string((1u << (counter_bits - 1)) - 1) +
                                " for a " + std::to_string(counter_bits) + "-bit counter");
  if (e.sync_frames < 1) throw std::invalid_argument(w + ": e2e.sync_frames must be >= 1");
  if (e.recovery_frames < 1) throw std::invalid_argument(w + ": e2e.recovery_frames must be >= 1");
  if (!(e.ramp_mA_per_s > 0) || !std::isfinite(e.ramp_mA_per_s))
    throw std::invalid_argument(w + ": e2e.ramp_mA_per_s must be > 0 [mA/s]");
}

SeqTracker make_tracker(std::uint32_t bits, const E2EConfig& e) {
  SeqTracker t;
  t.bits = bits;
  t.max_delta = e.max_counter_delta;
  t.sync_frames = e.sync_frames;
  return t;
}

}  // namespace

const char* to_string(NodeState s) noexcept {
  switch (s) {
    case NodeState::startup: return "startup";
    case NodeState::connected: return "connected";
    case NodeState::running: return "running";
    case NodeState::degraded: return "degraded";
    case NodeState::safe: return "safe";
    case NodeState::failed: return "failed";
  }
  return "?";
}

const char* to_string(NodeEventKind k) noexcept {
  switch (k) {
    case NodeEventKind::connect_sent: return "ccp_connect_sent";
    case NodeEventKind::connected: return "ccp_connected";
    case NodeEventKind::input_valid: return "input_valid_running";
    case NodeEventKind::input_implausible: return "input_implausible_degraded";
    case NodeEventKind::input_stale: return "input_stale_degraded";
    case NodeEventKind::ramp_done: return "ramp_done_safe_state";
    case NodeEventKind::sensor_timeout: return "sensor_timeout_safe_state";
    case NodeEventKind::input_recovered: return "input_recovered";
    case NodeEventKind::input_resumed: return "input_resumed";
    case NodeEventKind::dto_timeout: return "dto_timeout";
  }
  return "?";
}

// ----------------------------------------------------------------------------- slave

SlaveNode::SlaveNode(const BenchLayout& layout, SlaveConfig config)
    : layout_(layout), cfg_(std::move(config)), plant_(cfg_.plant) {
  if (cfg_.dto_reply.empty()) throw std::invalid_argument("slave: the recorded DTO reply is empty");
  validate(cfg_.e2e, layout_.command_counter_bits(), "slave");
  if (cfg_.stale_periods < 1) throw std::invalid_argument("slave: stale_periods must be >= 1");
  if (!std::isfinite(cfg_.current_min_mA) || !std::isfinite(cfg_.current_max_mA) ||
      !(cfg_.current_min_mA < cfg_.current_max_mA))
    throw std::invalid_argument("slave: the current driver's range must be finite with min < max [mA]");
  cmd_ = make_tracker(layout_.command_counter_bits(), cfg_.e2e);
  ramp_step_mA_ = cfg_.e2e.ramp_mA_per_s * cfg_.plant.dt_s;
  current_mA_ = command_mA_ = cfg_.current_min_mA;
  plant_.reset(0.0);
  if (cfg_.rig) {
    cfg_.rig->params.validate();
    for (const auto& c : cfg_.rig->drift) {
      c.before.validate();
      c.after.validate();
    }
    rig_.emplace(cfg_.rig->params, cfg_.plant.dt_s, cfg_.rig->seed);
  }
  log_.resize(cfg_.log_capacity);
}

void SlaveNode::reply_dto(can::Bus& bus) noexcept {
  for (const auto& f : cfg_.dto_reply) {
    if (bus.send(f))
      ++sent_;
    else
      ++send_fail_;
  }
  ++dto_replies_;
}

bool SlaveNode::wait_connect(can::Bus& bus, std::chrono::nanoseconds timeout) {
  const std::int64_t end = rt::monotonic_ns() + timeout.count();
  for (;;) {
    const std::int64_t left = end - rt::monotonic_ns();
    auto f = bus.receive(std::chrono::nanoseconds(left > 0 ? left : 0));
    if (!f) return false;
    if (layout_.is_connect(*f)) {
      reply_dto(bus);
      if (state_ == SlaveState::startup) go(SlaveState::connected, NodeEventKind::connected, 0.0);
      return true;
    }
    ++ignored_;
  }
}

void SlaveNode::go(SlaveState to, NodeEventKind why, double now_s) noexcept {
  events_.add(NodeEvent{step_, now_s, why, state_, to});
  state_ = to;
}

void SlaveNode::step(can::Bus& bus, double now_s) noexcept {
  // 1. Read what arrived since the last step (bounded); check every command frame.
  bool fresh = false, bad = false;
  std::uint16_t dropped = 0;
  for (std::size_t i = 0; i < kMaxDrain; ++i) {
    auto f = bus.receive(std::chrono::nanoseconds(0));
    if (!f) break;
    if (!f->extended && f->id == layout_.command_id) {
      ++cmd_.received;
      CommandMsg c;
      if (const auto why = layout_.check_command(*f, c)) {
        cmd_.on_drop(*why);
        bad = true;
        ++dropped;
        continue;
      }
      if (!cmd_.on_counter(c.counter)) {
        bad = true;
        ++dropped;
        continue;
      }
      // B current (scenario rig only: A − B) and restrictor command are not modelled by the B1 plant
      command_mA_ = rig_ ? c.solenoid_a_mA - c.solenoid_b_mA : c.solenoid_a_mA;
      fresh = true;
    } else if (layout_.is_connect(*f)) {
      reply_dto(bus);
    } else {
      ++ignored_;
    }
  }
  cmd_.end_step();
  watch_.end_step(fresh, bad);

  // 2. Safe-state machine (nodes.hpp).
  const auto ramp = [&]() noexcept { current_mA_ = std::max(cfg_.current_min_mA, current_mA_ - ramp_step_mA_); };
  const bool recovered = watch_.good_run >= cfg_.e2e.recovery_frames;
  switch (state_) {
    case SlaveState::startup:  // stepped without a CONNECT (simulations): as connected
    case SlaveState::connected:
      if (fresh && !bad) {
        go(SlaveState::running, NodeEventKind::input_valid, now_s);
        current_mA_ = command_mA_;
      }
      break;
    case SlaveState::running:
      if (bad) {
        go(SlaveState::degraded, NodeEventKind::input_implausible, now_s);
        ramp();
      } else if (fresh) {
        current_mA_ = command_mA_;
      } else if (watch_.misses >= cfg_.stale_periods) {
        go(SlaveState::degraded, NodeEventKind::input_stale, now_s);
        ramp();
      }  // else: hold the last command (a late frame)
      break;
    case SlaveState::degraded:
      if (recovered) {
        go(SlaveState::running, NodeEventKind::input_recovered, now_s);
        current_mA_ = command_mA_;
      } else {
        ramp();
      }
      break;
    case SlaveState::safe:
      current_mA_ = cfg_.current_min_mA;
      if (recovered) {
        go(SlaveState::running, NodeEventKind::input_resumed, now_s);
        current_mA_ = command_mA_;
      }
      break;
    default: break;
  }
  if (state_ == SlaveState::degraded && current_mA_ <= cfg_.current_min_mA)
    go(SlaveState::safe, NodeEventKind::ramp_done, now_s);

  // 3. The current driver: never outside its range, whatever was decided above.
  double i = current_mA_;
  const double lo = rig_ ? -cfg_.current_max_mA : cfg_.current_min_mA;  // the scenario rig: both solenoids
  if (!(i >= lo)) i = lo;  // also NaN
  if (i > cfg_.current_max_mA) i = cfg_.current_max_mA;
  current_mA_ = i;

  // 4. Plant and sensor frame. A scenario's rig: step s applies the command of control step
  // s − 1, so a drift at control step m reaches the rig from slave step m + 1 on.
  double y = 0.0, p_true = 0.0;
  std::uint16_t raw = 0;
  if (rig_) {
    if (step_ >= 1)
      if (const rigs::PilotValveRigParams* p = drift_.advance(cfg_.rig->drift, static_cast<std::int64_t>(step_) - 1))
        rig_->set_params(*p);
    // The rig's bias-corrected pressure difference, offset into the sensor code's range.
    raw = encode_pressure_raw(rig_->step(i) + kScenarioPressureZero_kPa);
    y = decode_pressure_raw(raw) - kScenarioPressureZero_kPa;
    p_true = rig_->true_pressure_kPa();
  } else {
    plant_.apply(i);
    y = plant_.measure();
    raw = plant_.last_raw();
    p_true = plant_.true_pressure_kPa();
  }
  SensorMsg s;
  s.pilot_raw = raw;
  s.supply_raw = 0;  // supply pressure is not modelled: sent as 0 (thesis Fig 2.17)
  s.counter = static_cast<std::uint16_t>(step_);
  if (bus.send(layout_.pack_sensors(s)))
    ++sent_;
  else
    ++send_fail_;
  if (n_log_ < log_.size())
    log_[n_log_++] =
        SlaveStepLog{step_, state_, cmd_.extended, fresh, dropped, i, p_true, y, s.pilot_raw};
  ++step_;
}

// ----------------------------------------------------------------------------- master

MasterNode::MasterNode(const BenchLayout& layout, MasterConfig config)
    : layout_(layout),
      cfg_(std::move(config)),
      controller_(cfg_.controller),
      reference_(cfg_.reference, cfg_.controller.pid.dt_s) {
  if (cfg_.fault_missed_periods == 0) throw std::invalid_argument("master: fault_missed_periods must be >= 1");
  if (cfg_.cro_retry_steps == 0) throw std::invalid_argument("master: cro_retry_steps must be >= 1");
  if (!(cfg_.dto_timeout_s > 0)) throw std::invalid_argument("master: dto_timeout_s must be > 0");
  validate(cfg_.e2e, layout_.sensor_counter_bits(), "master");
  if (cfg_.law) {
    const CompensatedLaw& c = *cfg_.law;
    if (std::fabs(c.pid.dt_s - cfg_.controller.pid.dt_s) > 1e-12 * cfg_.controller.pid.dt_s)
      throw std::invalid_argument("master: the scenario law's dt differs from the step");
    if (!(c.command_min <= c.command_max) || !std::isfinite(c.feedforward))
      throw std::invalid_argument("master: the scenario law needs command_min <= command_max and a finite feedforward");
    pid_.emplace(c.pid);
    comp_.emplace(c.compensation);
  }
  sens_ = make_tracker(layout_.sensor_counter_bits(), cfg_.e2e);
  ramp_step_mA_ = cfg_.e2e.ramp_mA_per_s * cfg_.controller.pid.dt_s;
  log_.resize(cfg_.log_capacity);
  bus_log_.resize(cfg_.bus_log_capacity ? cfg_.bus_log_capacity : 4 * cfg_.log_capacity + 64);
  cal_ = initial_calibration(cfg_);
  cal_events_.resize(1024);
}

CalibrationPage initial_calibration(const MasterConfig& c) noexcept {
  CalibrationPage p;
  const PidGains& g = c.law ? c.law->pid.gains : c.controller.pid.gains;
  p.kp = g.kp;
  p.ki_per_s = g.ki_per_s;
  p.kd_s = g.kd_s;
  p.n_per_s = g.n_per_s;
  const DeadzoneInverseParams& n = c.law ? c.law->compensation.nominal : c.controller.dz_inverse;
  p.dz_right_mA = n.offset_right;
  p.dz_left_mA = n.offset_left;
  p.compensation = static_cast<double>(c.law ? c.law->compensation.mode : CompensationMode::fixed);
  const AdaptationSettings a = c.law ? c.law->compensation.adaptation : AdaptationSettings{};
  p.adapt_rate_mA_per_s = a.rate_limit_per_s;
  p.adapt_tolerance = a.tolerance_ratio;
  p.adapt_settle_s = a.settle_s;
  p.dither_mA = a.dither_amplitude;
  return p;
}

namespace {
// A page's compensation value as a mode (the XCP slave admits only the integers 0..2).
CompensationMode mode_of(double v) noexcept {
  return v <= 0.5 ? CompensationMode::none
                  : (v <= 1.5 ? CompensationMode::fixed : (v <= 2.5 ? CompensationMode::adaptive : CompensationMode::oracle));
}
}  // namespace

// A new calibration page at a step boundary: the law's gains, the compensation (mode, nominal
// edges, adaptation settings) and the reference offset change together, before the step's law
// runs; one event per object that changed.
//  - scenario law: the PID's gains; the compensator's nominal edges (set_nominal), adaptation
//    settings (set_adaptation) and mode (set_mode), each only when it changed (a new nominal or
//    mode restarts the compensation from the nominal inverse; adaptive_compensator.hpp);
//  - bench controller: the PID's gains; its fixed inverse gets the edges, or 0 for
//    compensation 0 (none); compensation 2 acts as 1 (no estimator), the adaptation settings
//    have no effect (logged all the same).
void MasterNode::apply_calibration(const CalibrationPage& p, double now_s) noexcept {
  const auto fields = calibration_fields();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const double before = cal_.*fields[i].member, after = p.*fields[i].member;
    if (before == after) continue;
    if (n_cal_events_ < cal_events_.size())
      cal_events_[n_cal_events_++] = CalibrationEvent{k_, now_s, static_cast<std::uint16_t>(i), before, after};
  }
  const CalibrationPage before = cal_;
  cal_ = p;
  const PidGains g{p.kp, p.ki_per_s, p.kd_s, p.n_per_s};
  controller_.pid().set_gains(g);
  if (pid_) pid_->set_gains(g);
  const CompensationMode mode = mode_of(p.compensation);
  if (comp_) {
    if (p.dz_right_mA != before.dz_right_mA || p.dz_left_mA != before.dz_left_mA)
      comp_->set_nominal(p.dz_right_mA, p.dz_left_mA);
    if (p.adapt_rate_mA_per_s != before.adapt_rate_mA_per_s || p.adapt_tolerance != before.adapt_tolerance ||
        p.adapt_settle_s != before.adapt_settle_s || p.dither_mA != before.dither_mA) {
      AdaptationSettings a = comp_->config().adaptation;
      a.rate_limit_per_s = p.adapt_rate_mA_per_s;
      a.tolerance_ratio = p.adapt_tolerance;
      a.settle_s = p.adapt_settle_s;
      a.dither_amplitude = p.dither_mA;
      comp_->set_adaptation(a);  // inside the limits: valid (a refusal would keep the old settings)
    }
    comp_->set_mode(mode);
  }
  if (mode == CompensationMode::none)
    controller_.deadzone_inverse().set_offsets(0.0, 0.0);
  else
    controller_.deadzone_inverse().set_offsets(p.dz_right_mA, p.dz_left_mA);
}

void MasterNode::go(MasterState to, NodeEventKind why, double now_s) noexcept {
  events_.add(NodeEvent{k_, now_s, why, state_, to});
  state_ = to;
}

void MasterNode::record(const can::Frame& f, bool sent) noexcept {
  if (n_bus_log_ < bus_log_.size())
    bus_log_[n_bus_log_++] = LoggedFrame{f, sent};
  else
    ++bus_log_dropped_;
}

void MasterNode::send(can::Bus& bus, const can::Frame& f, double now_s) noexcept {
  can::Frame g = f;
  g.timestamp_s = now_s;
  if (bus.send(g)) {
    ++sent_;
    record(g, true);
  } else {
    ++send_fail_;
  }
}

bool MasterNode::step(can::Bus& bus, double now_s) noexcept {
  if (state_ == MasterState::failed) return false;
  // 0. Step boundary: the newest calibration page (XCP thread, or the replayed schedule).
  if (link_) {
    CalibrationPage p;
    bool got = false;
    while (link_->pages.pop(p)) got = true;
    if (got && !(p == cal_)) apply_calibration(p, now_s);
  }
  while (next_change_ < cfg_.calibration_schedule.size() &&
         cfg_.calibration_schedule[next_change_].control_step <= m_ + 1) {
    const CalibrationPage& p = cfg_.calibration_schedule[next_change_++].page;
    if (!(p == cal_)) apply_calibration(p, now_s);
  }
  // 1. Read what arrived since the last step (bounded); check every sensor frame.
  bool dto = false;
  fresh_ = bad_ = false;
  std::uint16_t dropped = 0;
  for (std::size_t i = 0; i < kMaxDrain; ++i) {
    auto f = bus.receive(std::chrono::nanoseconds(0));
    if (!f) break;
    if (!f->extended && f->id == layout_.sensors_id) {
      record(*f, false);
      ++sens_.received;
      SensorMsg s;
      if (const auto why = layout_.check_sensors(*f, s)) {
        sens_.on_drop(*why);
        bad_ = true;
        ++dropped;
        continue;
      }
      if (!sens_.on_counter(s.counter)) {
        bad_ = true;
        ++dropped;
        continue;
      }
      measured_kPa_ = decode_pressure_raw(s.pilot_raw) - (comp_ ? kScenarioPressureZero_kPa : 0.0);
      sensor_counter_ = s.counter;
      fresh_ = true;
    } else if (layout_.is_connect_ack(*f)) {
      record(*f, false);
      dto = true;
    } else {
      ++ignored_;
    }
  }
  sens_.end_step();
  watch_.end_step(fresh_, bad_);

  // 2. CCP handshake.
  if (state_ == MasterState::startup) {
    if (dto && cro_sent_) {
      handshake_s_ = now_s - first_cro_s_;
      reset_law();
      // The sensor timeout counts from the connection: the steps spent waiting for the DTO are
      // not missed sensor periods (the slave sends only once connected). A replay of the logs
      // (hil simulate --schedule) starts at the connection too, so it must not see them either.
      watch_ = InputWatch{};
      go(MasterState::connected, NodeEventKind::connected, now_s);
    } else if (cro_sent_ && now_s - first_cro_s_ >= cfg_.dto_timeout_s) {
      go(MasterState::failed, NodeEventKind::dto_timeout, now_s);
    } else if (!cro_sent_ || k_ - last_cro_k_ >= cfg_.cro_retry_steps) {
      send(bus, layout_.pack_connect(cro_ctr_), now_s);
      if (!cro_sent_) {
        first_cro_s_ = now_s;
        events_.add(NodeEvent{k_, now_s, NodeEventKind::connect_sent, state_, state_});
      }
      cro_sent_ = true;
      last_cro_k_ = k_;
    }
  }

  // 3. Safe-state machine (nodes.hpp) and the control law.
  const bool send_cmd = state_ != MasterState::startup && state_ != MasterState::failed;
  double r = 0.0;
  if (send_cmd) {
    ++m_;
    r = reference_.next() + cal_.reference_offset_kPa;
    control(bus, r, now_s);
  }
  if (send_cmd) {
    CommandMsg c;
    c.solenoid_a_mA = current_mA_ > 0.0 ? current_mA_ : 0.0;
    if (comp_ && current_mA_ < 0.0) c.solenoid_b_mA = -current_mA_;  // scenario law: both solenoids
    c.counter = cmd_counter_;
    send(bus, layout_.pack_command(c), now_s);
    ++cmd_counter_;
  }
  if (n_log_ < log_.size()) {
    MasterStepLog& l = log_[n_log_++];
    l.step = k_;
    l.control_step = m_;
    l.state = state_;
    l.reference_kPa = r;
    l.measured_kPa = measured_kPa_;
    l.sensor_counter = sensor_counter_;
    l.sensor_fresh = fresh_;
    l.sensor_seq = fresh_ ? static_cast<std::int64_t>(sens_.extended) : -1;
    l.dropped = dropped;
    l.current_mA = send_cmd ? current_mA_ : 0.0;
    l.integrator_mA = pid_ ? pid_->integrator() : controller_.pid().integrator();
    if (comp_ && comp_->config().mode != CompensationMode::none) {
      l.inverse_right_mA = comp_->inverse().params().offset_right;
      l.inverse_left_mA = -comp_->inverse().params().offset_left;
    }
    l.command_counter = static_cast<std::uint16_t>(cmd_counter_ - (send_cmd ? 1 : 0));
    l.command_sent = send_cmd;
    l.calibration = cal_;
  }
  if (link_) {  // DAQ event channel 0: this step's measurements (never waits; a full queue is counted)
    MeasurementSample m;
    m.step = k_;
    m.t_us = static_cast<std::int64_t>(std::llround(now_s * 1e6));
    m.page.reference_kPa = r;
    m.page.measured_kPa = measured_kPa_;
    m.page.current_mA = send_cmd ? current_mA_ : 0.0;
    m.page.integrator_mA = pid_ ? pid_->integrator() : controller_.pid().integrator();
    m.page.control_step = static_cast<double>(m_);
    m.page.state = static_cast<double>(state_);
    m.page.sensor_fresh = fresh_ ? 1.0 : 0.0;
    m.page.dropped = static_cast<double>(dropped);
    m.page.tet_us = loop_tet_us_;  // console status (docs/console.md): the loop's figures, the frame counters
    m.page.wake_latency_us = loop_wake_us_;
    m.page.overruns = loop_overruns_;
    m.page.frames_late = static_cast<double>(sens_.late);
    m.page.frames_lost = static_cast<double>(sens_.lost);
    if (!link_->samples.push(m)) link_->samples_lost.fetch_add(1, std::memory_order_relaxed);
  }
  ++k_;
  return state_ != MasterState::failed;
}

// The control law of one sample: the bench's controller (PID → fixed offset → saturation) or a
// scenario's compensated law (nodes.hpp, CompensatedLaw).
double MasterNode::law(double r, double y) noexcept {
  if (!comp_) return controller_.step(r, y);
  const CompensatedLaw& c = *cfg_.law;
  const double u = pid_->step(r - y) + c.feedforward * r;
  if (c.oracle) {  // the plant's true edges of this control step (rigs/drift.hpp)
    if (!oracle_started_) {
      comp_->set_oracle(c.oracle->params.deadzone_right_mA, -c.oracle->params.deadzone_left_mA);
      oracle_started_ = true;
    }
    if (const rigs::PilotValveRigParams* p = oracle_.advance(c.oracle->drift, m_))
      comp_->set_oracle(p->deadzone_right_mA, -p->deadzone_left_mA);
  }
  double i = comp_->command(u);
  i = i < c.command_min ? c.command_min : (i > c.command_max ? c.command_max : i);
  comp_->observe(i, y, true);  // law() runs on a fresh sensor value only (control())
  law_ran_ = true;
  return i;
}

void MasterNode::reset_law() noexcept {
  controller_.reset();
  if (pid_) pid_->reset();
}

CompensationState MasterNode::compensation() const noexcept {
  return comp_ ? compensation_state(*comp_) : CompensationState{};
}

// One control step in states connected..safe: sets current_mA_.
void MasterNode::control(can::Bus& bus, double r, double now_s) noexcept {
  law_ran_ = false;
  control_states(bus, r, now_s);
  // A control step whose law did not run on a fresh sensor value (a late frame: the command is
  // held; degraded, safe, not yet running) is a gap for the adaptive compensator: the
  // estimator is restarted and not updated, the inverse keeps its parameters
  // (DeadzoneCompensator::observe with fresh = false, docs/compensation.md).
  if (comp_ && !law_ran_) comp_->observe(current_mA_, measured_kPa_, false);
}

void MasterNode::control_states(can::Bus& bus, double r, double now_s) noexcept {
  const double safe_mA = cfg_.controller.current_min_mA;
  const bool stale = watch_.misses >= cfg_.fault_missed_periods;
  const bool recovered = watch_.good_run >= cfg_.e2e.recovery_frames;
  auto to_safe = [&](NodeEventKind why) noexcept {
    go(MasterState::safe, why, now_s);
    current_mA_ = safe_mA;
    last_cro_k_ = k_;
  };
  switch (state_) {
    case MasterState::connected:
      if (fresh_ && !bad_) {
        go(MasterState::running, NodeEventKind::input_valid, now_s);
        current_mA_ = law(r, measured_kPa_);
      } else if (stale) {
        to_safe(NodeEventKind::sensor_timeout);
      } else {
        current_mA_ = safe_mA;
      }
      break;
    case MasterState::running:
      if (bad_) {
        go(MasterState::degraded, NodeEventKind::input_implausible, now_s);
      } else if (fresh_) {
        current_mA_ = law(r, measured_kPa_);
      } else if (stale) {
        // No forget(): frames missed now are counted lost when the counter resumes; a restarted
        // slave (counter back at 0) re-synchronises after sync_frames frames.
        to_safe(NodeEventKind::sensor_timeout);
      }  // else: hold the last command for up to N − 1 missed periods (a late frame)
      break;
    case MasterState::degraded:
      if (stale) {
        to_safe(NodeEventKind::sensor_timeout);
      } else if (recovered) {  // the PID resumes where it was frozen
        go(MasterState::running, NodeEventKind::input_recovered, now_s);
        current_mA_ = law(r, measured_kPa_);
      }
      break;
    case MasterState::safe:
      current_mA_ = safe_mA;
      if (recovered) {
        go(MasterState::running, NodeEventKind::input_resumed, now_s);
        reset_law();
        current_mA_ = law(r, measured_kPa_);
      } else if (stale && k_ - last_cro_k_ >= cfg_.cro_retry_steps) {  // reconnect a restarted slave
        send(bus, layout_.pack_connect(cro_ctr_), now_s);
        last_cro_k_ = k_;
      }
      break;
    default: break;
  }
  if (state_ == MasterState::degraded) {  // PID frozen (not stepped): ramp the held command to the safe one
    current_mA_ = std::max(safe_mA, current_mA_ - ramp_step_mA_);
    if (current_mA_ <= safe_mA) go(MasterState::safe, NodeEventKind::ramp_done, now_s);
  }
}

}  // namespace lash::hil
