// hoist-dash page: the channel vocabulary (channel suffixes from hoist_msgs.js,
// generated from msgs/*.lcm) and the page's shared state.
import { CHANNELS } from "./hoist_msgs.js";

// Channel suffixes (what follows a shaft's prefix): the wire channels of
// msgs/*.lcm, and the ones hoist-dash derives from them (the decimated cage
// state and load estimate, the cage history).
export const channelOf = (type) => {
  const c = CHANNELS[type];
  if (typeof c !== "string") throw new Error(`hoist_msgs.js names no channel for ${type}`);
  return c;
};
export const CH = {
  cage: channelOf("hoist.cage_state_t"), shape: channelOf("hoist.guide_shape_t"), alarm: channelOf("hoist.alarm_t"),
  ack: channelOf("hoist.alarm_ack_t"), health: channelOf("hoist.health_t"), forecast: channelOf("hoist.forecast_t"),
  plan: channelOf("hoist.trip_plan_t"), estimate: channelOf("hoist.estimate_t"),
};
CH.history = `${CH.cage}/history`;
CH.cageDecimated = `${CH.cage}/decimated`;
CH.estimateDecimated = `${CH.estimate}/decimated`;
// Longest first: a topic belongs to the longest suffix it ends with.
export const SUFFIXES = [...Object.values(CHANNELS), CH.history, CH.cageDecimated, CH.estimateDecimated]
  .sort((a, b) => b.length - a.length);
export const SUBSCRIBE = new Set([CH.history, CH.cageDecimated, CH.shape, CH.alarm, CH.health, CH.forecast, CH.plan,
                           CH.estimateDecimated]);
export const STALE_AFTER_MS = 1500;     // STALE shown within 2 s of silence
export const KEEP_S = 300;              // longest trend window

export const state = {
  ws: null, client: null, readOnly: true, meta: {}, channels: new Map(), subs: new Map(),
  shafts: new Map(), selected: null, ackChannels: new Map(),
  windowS: 60, notices: new Map(), alarmEvents: 0, historyQueue: [], historyPending: false,
};

// The operator name field (commands carry it; remembered in the browser).
export const userInput = document.querySelector("#user");
