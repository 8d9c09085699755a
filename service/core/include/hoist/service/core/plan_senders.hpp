// hoist/service/core/plan_senders.hpp -- the trip-plan sequence rule, per sender
// (msgs/trip_plan_t.lcm: sender_id).  Pure, fixed size: no I/O, no
// allocation (the daemon applies it in its receive path).
//
//   * A plan from sender S whose seq is not above the last seq accepted from
//     S is old -- unless S's last accepted plan has expired (older than
//     [forecast] plan_timeout of model time, either way: model time restarts
//     with a new winder stream): then any seq is new again, so a restarted
//     controller that starts over at seq 0 is heard after one timeout.
//   * Senders do not share a sequence: a plan from another sender (a forged
//     one with seq = INT64_MAX included) never makes S's plans old.  The
//     newest accepted plan of any sender is the one in force.
//   * kSenders senders are remembered; a new one takes an expired entry, or
//     else the entry accepted longest ago (never the plan in force).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace hoist::service::inline core {

class PlanSenders {
 public:
  static constexpr int kSenders = 8;

  /// Whether (sender, seq) at model time `t` is old (to be rejected); when it
  /// is, `last_seq` and `last_t` say what was accepted from that sender.
  bool isOld(std::int64_t sender, std::int64_t seq, double t, double timeout, std::int64_t& last_seq,
             double& last_t) const {
    for (const Entry& e : e_)
      if (e.used && e.sender == sender) {
        if (expired(e, t, timeout) || seq > e.seq) return false;
        last_seq = e.seq;
        last_t = e.t;
        return true;
      }
    return false;
  }

  /// A plan (sender, seq) was accepted at model time `t`.
  void accept(std::int64_t sender, std::int64_t seq, double t, double timeout) {
    Entry* slot = nullptr;
    for (Entry& e : e_)
      if (e.used && e.sender == sender) slot = &e;
    if (!slot)
      for (Entry& e : e_)
        if (!e.used || expired(e, t, timeout)) {
          slot = &e;
          break;
        }
    if (!slot) {  // all in use: the one accepted longest ago (order of acceptance, not model time)
      slot = &e_[0];
      for (Entry& e : e_)
        if (e.order < slot->order) slot = &e;
    }
    *slot = Entry{true, sender, seq, t, ++order_};
  }

 private:
  struct Entry {
    bool used = false;
    std::int64_t sender = 0;
    std::int64_t seq = 0;
    double t = 0.0;           ///< model time of its last accepted plan [s]
    std::uint64_t order = 0;  ///< acceptance counter (larger: more recent)
  };
  static bool expired(const Entry& e, double t, double timeout) { return !(std::fabs(t - e.t) <= timeout); }
  std::array<Entry, kSenders> e_{};
  std::uint64_t order_ = 0;
};

}  // namespace hoist::service::core
