#include "lash/hil/nodes.hpp"

#include <stdexcept>

#include "lash/rt/periodic.hpp"

namespace lash::hil {

bool SeqTracker::on_frame(std::uint16_t counter) noexcept {
  ++received;
  ++in_step;
  if (!have) {
    have = true;
    last = counter;
    return true;
  }
  const std::uint16_t d = counter_delta(last, counter);
  if (d == 0) {
    ++duplicates;
    return false;
  }
  if (d >= 1024) {
    ++resyncs;  // a restarted peer, or a frame older than anything plausible
  } else {
    lost += d - 1u;
  }
  last = counter;
  return true;
}

// ----------------------------------------------------------------------------- slave

SlaveNode::SlaveNode(const BenchLayout& layout, SlaveConfig config)
    : layout_(layout), cfg_(std::move(config)), plant_(cfg_.plant) {
  if (cfg_.dto_reply.empty()) throw std::invalid_argument("slave: the recorded DTO reply is empty");
  plant_.reset(0.0);
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
      return true;
    }
    ++ignored_;
  }
}

void SlaveNode::step(can::Bus& bus, double now_s) noexcept {
  (void)now_s;
  bool fresh = false;
  for (std::size_t i = 0; i < kMaxDrain; ++i) {
    auto f = bus.receive(std::chrono::nanoseconds(0));
    if (!f) break;
    if (!f->extended && f->id == layout_.command_id && f->len >= layout_.command_len) {
      const CommandMsg c = layout_.unpack_command(*f);
      if (cmd_.on_frame(c.counter)) {
        current_mA_ = c.solenoid_a_mA;  // B current and restrictor command are not modelled
        cmd_counter_ = c.counter;
        fresh = true;
      }
    } else if (layout_.is_connect(*f)) {
      reply_dto(bus);
    } else {
      ++ignored_;
    }
  }
  cmd_.end_step();
  plant_.apply(current_mA_);
  const double y = plant_.measure();
  SensorMsg s;
  s.pilot_raw = plant_.last_raw();
  s.supply_raw = 0;  // supply pressure is not modelled: sent as 0 (thesis Fig 2.17)
  s.counter = static_cast<std::uint16_t>(step_);
  if (bus.send(layout_.pack_sensors(s)))
    ++sent_;
  else
    ++send_fail_;
  if (n_log_ < log_.size())
    log_[n_log_++] = SlaveStepLog{step_, cmd_counter_, fresh, current_mA_, plant_.true_pressure_kPa(), y, s.pilot_raw};
  ++step_;
}

// ----------------------------------------------------------------------------- master

const char* to_string(MasterState s) noexcept {
  switch (s) {
    case MasterState::connecting: return "connecting";
    case MasterState::running: return "running";
    case MasterState::fault: return "fault";
    case MasterState::failed: return "failed";
  }
  return "?";
}

const char* to_string(MasterEventKind k) noexcept {
  switch (k) {
    case MasterEventKind::connect_sent: return "ccp_connect_sent";
    case MasterEventKind::connected: return "ccp_connected";
    case MasterEventKind::sensor_timeout: return "sensor_timeout_safe_state";
    case MasterEventKind::sensor_resumed: return "sensor_resumed";
    case MasterEventKind::dto_timeout: return "dto_timeout";
  }
  return "?";
}

MasterNode::MasterNode(const BenchLayout& layout, MasterConfig config)
    : layout_(layout),
      cfg_(std::move(config)),
      controller_(cfg_.controller),
      reference_(cfg_.reference, cfg_.controller.pid.dt_s) {
  if (cfg_.fault_missed_periods == 0) throw std::invalid_argument("master: fault_missed_periods must be >= 1");
  if (cfg_.cro_retry_steps == 0) throw std::invalid_argument("master: cro_retry_steps must be >= 1");
  if (!(cfg_.dto_timeout_s > 0)) throw std::invalid_argument("master: dto_timeout_s must be > 0");
  log_.resize(cfg_.log_capacity);
  events_.resize(256);
  bus_log_.resize(cfg_.bus_log_capacity ? cfg_.bus_log_capacity : 4 * cfg_.log_capacity + 64);
}

void MasterNode::event(MasterEventKind kind, double now_s) noexcept {
  if (n_events_ < events_.size()) events_[n_events_++] = MasterEvent{k_, now_s, kind};
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
  // 1. Read what arrived since the last step (bounded).
  bool dto = false, fresh = false;
  for (std::size_t i = 0; i < kMaxDrain; ++i) {
    auto f = bus.receive(std::chrono::nanoseconds(0));
    if (!f) break;
    if (!f->extended && f->id == layout_.sensors_id && f->len >= layout_.sensors_len) {
      record(*f, false);
      const SensorMsg s = layout_.unpack_sensors(*f);
      if (sens_.on_frame(s.counter)) {
        measured_kPa_ = decode_pressure_raw(s.pilot_raw);
        sensor_counter_ = s.counter;
        have_measurement_ = true;
        fresh = true;
      }
    } else if (layout_.is_connect_ack(*f)) {
      record(*f, false);
      dto = true;
    } else {
      ++ignored_;
    }
  }
  sens_.end_step();

  // 2. State machine.
  bool send_cmd = false;
  if (state_ == MasterState::connecting) {
    if (dto && cro_sent_) {
      state_ = MasterState::running;
      handshake_s_ = now_s - first_cro_s_;
      controller_.reset();
      misses_ = 0;
      event(MasterEventKind::connected, now_s);
    } else {
      if (cro_sent_ && now_s - first_cro_s_ >= cfg_.dto_timeout_s) {
        state_ = MasterState::failed;
        event(MasterEventKind::dto_timeout, now_s);
      } else if (!cro_sent_ || k_ - last_cro_k_ >= cfg_.cro_retry_steps) {
        send(bus, layout_.pack_connect(cro_ctr_), now_s);
        if (!cro_sent_) {
          first_cro_s_ = now_s;
          event(MasterEventKind::connect_sent, now_s);
        }
        cro_sent_ = true;
        last_cro_k_ = k_;
      }
    }
  }
  double r = 0.0;
  if (state_ == MasterState::running || state_ == MasterState::fault) {
    ++m_;
    r = reference_.next();
    send_cmd = true;
    if (state_ == MasterState::fault && fresh) {
      state_ = MasterState::running;
      controller_.reset();
      event(MasterEventKind::sensor_resumed, now_s);
    }
    if (state_ == MasterState::running) {
      if (fresh) {
        misses_ = 0;
        current_mA_ = controller_.step(r, measured_kPa_);
      } else if (++misses_ >= cfg_.fault_missed_periods) {
        state_ = MasterState::fault;
        current_mA_ = 0.0;  // safe state
        // No forget(): frames missed now are counted lost when the counter resumes; a restarted
        // slave (counter back at 0) shows up as a resync.
        last_cro_k_ = k_;
        event(MasterEventKind::sensor_timeout, now_s);
      } else if (!have_measurement_) {
        current_mA_ = 0.0;
      }  // else: hold the last command for up to N − 1 missed periods
    } else {
      current_mA_ = 0.0;
      if (k_ - last_cro_k_ >= cfg_.cro_retry_steps) {  // reconnect a restarted slave
        send(bus, layout_.pack_connect(cro_ctr_), now_s);
        last_cro_k_ = k_;
      }
    }
  }
  if (send_cmd) {
    CommandMsg c;
    c.solenoid_a_mA = current_mA_;
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
    l.sensor_fresh = fresh;
    l.current_mA = send_cmd ? current_mA_ : 0.0;
    l.command_counter = static_cast<std::uint16_t>(cmd_counter_ - (send_cmd ? 1 : 0));
    l.command_sent = send_cmd;
  }
  ++k_;
  return state_ != MasterState::failed;
}

}  // namespace lash::hil
