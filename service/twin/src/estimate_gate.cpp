// Which state the alarms judge: see hoist/service/twin/estimate_gate.hpp.
#include "hoist/service/twin/estimate_gate.hpp"

#include <algorithm>

namespace hoist::service::inline twin {

void EstimateGate::pushLoad(GateEvent::Type type, double t, double Fa, double M) {
  GateEvent e;
  e.type = type;
  e.t = t;
  e.Fa0 = Fa0_;
  e.M0 = M0_;
  e.Fa1 = Fa;
  e.M1 = M;
  push(e);
}

Judgement EstimateGate::worse(const Judgement& a, const Judgement& b) const {
  Judgement w = a;
  Clearance& c = w.clearance;
  c.excursion_pos = std::max(a.clearance.excursion_pos, b.clearance.excursion_pos);
  c.excursion_neg = std::max(a.clearance.excursion_neg, b.clearance.excursion_neg);
  c.guide_deflection = std::max(a.clearance.guide_deflection, b.clearance.guide_deflection);
  c.clearance_pos = alarms_.gap_pos_y - c.excursion_pos;
  c.clearance_neg = alarms_.gap_neg_y - c.excursion_neg;
  c.clearance_guide = alarms_.guide_rope_gap - c.guide_deflection;
  c.min_clearance = std::min({c.clearance_pos, c.clearance_neg, c.clearance_guide});
  w.lambda0_slack = std::min(a.lambda0_slack, b.lambda0_slack);
  w.lambda0_overload = std::max(a.lambda0_overload, b.lambda0_overload);
  return w;
}

const Judgement& EstimateGate::step(double t, bool usable, unsigned not_used, const Judgement& estimate,
                                    const Judgement& open_loop, std::int64_t load_changes, double Fa, double M) {
  const Judgement& fresh = usable ? estimate : open_loop;
  if (first_) {
    // The first step (or after a restart): nothing judged before to hold.
    first_ = false;
    changes_ = load_changes;
    hold_until_ = -1e300;
    change_pending_ = false;
  } else {
    const bool switched = usable != in_use_;
    const bool changed = load_changes != changes_;
    if (switched || changed) {
      // Hold what was judged until the new judgement has held clear_hold
      // (a hold running already keeps its held values: the more alarming).
      if (!holding(t)) held_ = judged_;
      hold_until_ = t + hold_;
    }
    if (switched) {
      ++switches_;
      GateEvent e;
      e.type = GateEvent::Type::Switch;
      e.t = t;
      e.to_estimate = usable;
      e.not_used = not_used;
      push(e);
    }
    if (changed) {
      if (!change_pending_) {
        Fa0_ = Fa_prev_;
        M0_ = M_prev_;
      }
      change_pending_ = true;
      changes_ = load_changes;
      pushLoad(GateEvent::Type::LoadChange, t, Fa, M);
    }
  }
  if (holding(t)) {
    judged_ = worse(fresh, held_);
  } else {
    judged_ = fresh;
    if (change_pending_) {
      change_pending_ = false;
      dFa_ = Fa - Fa0_;
      dM_ = M - M0_;
      pushLoad(GateEvent::Type::LoadSettled, t, Fa, M);
    }
  }
  in_use_ = usable;
  not_used_ = usable ? 0u : not_used;
  Fa_prev_ = Fa;
  M_prev_ = M;
  return judged_;
}

}  // namespace hoist::service::twin
