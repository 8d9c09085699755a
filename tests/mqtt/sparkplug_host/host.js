// An independent Sparkplug B host for hoist-mqtt's tests: decodes with the
// Eclipse Tahu payload package (npm sparkplug-payload) and talks MQTT with
// mqtt.js, so nothing of hoist-mqtt's own encoding is trusted.
//
//   node host.js BROKER_URL GROUP EDGE COMMAND_FILE
//
// It checks what a Sparkplug host relies on and prints, one line each:
//   MSG {...}     every message on spBv1.0/GROUP/# (decoded) and hoist/_bridge/+/health (JSON)
//   ERROR text    a violation: seq not continuous, a birth without bdSeq or
//                 Node Control/Rebirth or units, an alias used before its
//                 birth or changed across births, NDEATH bdSeq != NBIRTH bdSeq, ...
//   REPORT {...}  on the command "report": counts and the errors so far
// Commands, one per line appended to COMMAND_FILE:
//   dcmd DEVICE JSON_METRICS | ncmd JSON_METRICS | raw TOPIC HEX | state HOST true|false TIMESTAMP
//   flood DEVICE N RATE JSON_METRICS | report | quit
'use strict';
const fs = require('fs');
const mqtt = require('mqtt');
const sparkplug = require('sparkplug-payload').get('spBv1.0');

const [url, group, edge, cmdFile] = process.argv.slice(2);
const errors = [];
const counts = {};
let expectSeq = null;          // next seq of the node (null: no NBIRTH yet)
let birthBdSeq = null;         // bdSeq of the latest NBIRTH
const aliases = new Map();     // "device|name" -> alias, kept across births (consistency)
const aliasOwner = new Map();  // alias -> "device|name"
const born = new Map();        // device ('' = node) -> Map(alias -> {name, type})

function num(v) {
  if (v === null || v === undefined) return v;
  if (typeof v === 'object' && typeof v.toNumber === 'function') return v.toNumber();
  return v;
}
function err(text) {
  errors.push(text);
  console.log('ERROR ' + text);
}

const client = mqtt.connect(url, { clientId: 'sparkplug-test-host-' + process.pid, clean: true, reconnectPeriod: 200 });
client.on('connect', () => {
  client.subscribe([`spBv1.0/${group}/#`, 'hoist/_bridge/+/health'], { qos: 1 }, () => console.log('READY'));
});

function birth(device, metrics, kind) {
  const table = new Map();
  for (const m of metrics) {
    const alias = num(m.alias);
    if (m.name === undefined || alias === undefined || m.type === undefined)
      err(`${kind} ${device}: a metric without name, alias or datatype: ${JSON.stringify(m.name)}`);
    const key = device + '|' + m.name;
    if (aliases.has(key) && aliases.get(key) !== alias) err(`${kind} ${device}: '${m.name}' changed alias ${aliases.get(key)} -> ${alias}`);
    if (aliasOwner.has(alias) && aliasOwner.get(alias) !== key) err(`${kind}: alias ${alias} used by ${aliasOwner.get(alias)} and ${key}`);
    aliases.set(key, alias);
    aliasOwner.set(alias, key);
    table.set(alias, { name: m.name, type: m.type });
  }
  born.set(device, table);
}

client.on('message', (topic, payload) => {
  if (topic.startsWith('hoist/_bridge/')) {
    let j = null;
    try { j = JSON.parse(payload.toString()); } catch (e) { }
    console.log('MSG ' + JSON.stringify({ topic, json: j }));
    return;
  }
  const parts = topic.split('/');
  const type = parts[2], device = parts.length > 4 ? parts[4] : '';
  counts[type] = (counts[type] || 0) + 1;
  if (type === 'NCMD' || type === 'DCMD') return;  // commands (the tests' own, some malformed on purpose)
  let p;
  try {
    p = sparkplug.decodePayload(payload);
  } catch (e) {
    err(`${topic}: undecodable payload: ${e.message}`);
    return;
  }
  const metrics = (p.metrics || []).map((m) => ({
    name: m.name, alias: num(m.alias), type: m.type, value: num(m.value), timestamp: num(m.timestamp),
    historical: !!m.isHistorical, units: m.properties && m.properties.engUnit ? m.properties.engUnit.value : undefined,
  }));
  const seq = p.seq === undefined ? undefined : num(p.seq);
  console.log('MSG ' + JSON.stringify({ topic, type, device, seq, timestamp: num(p.timestamp), metrics }));
  if (type === 'NDEATH') {
    if (seq !== undefined) err('NDEATH with a seq');
    const bd = metrics.find((m) => m.name === 'bdSeq');
    if (!bd) err('NDEATH without bdSeq');
    else if (birthBdSeq !== null && bd.value !== birthBdSeq) err(`NDEATH bdSeq ${bd.value} != NBIRTH bdSeq ${birthBdSeq}`);
    counts.ndeath_bdseq_match = (counts.ndeath_bdseq_match || 0) + (bd && bd.value === birthBdSeq ? 1 : 0);
    expectSeq = null;
    return;
  }
  if (seq === undefined || seq < 0 || seq > 255) { err(`${topic}: seq missing or outside 0..255: ${seq}`); return; }
  if (type === 'NBIRTH') {
    const bd = metrics.find((m) => m.name === 'bdSeq');
    const rb = metrics.find((m) => m.name === 'Node Control/Rebirth');
    if (!bd) err('NBIRTH without bdSeq');
    if (!rb || rb.type !== 'Boolean' || rb.value !== false) err('NBIRTH without Node Control/Rebirth = false');
    if (seq !== 0) err(`NBIRTH seq ${seq} (expected 0)`);
    birthBdSeq = bd ? bd.value : null;
    birth('', p.metrics || [], 'NBIRTH');
    expectSeq = (seq + 1) % 256;
    return;
  }
  if (expectSeq === null) { err(`${topic} before any NBIRTH`); return; }
  if (seq !== expectSeq) err(`${topic}: seq ${seq}, expected ${expectSeq}`);
  expectSeq = (seq + 1) % 256;
  if (type === 'DBIRTH') {
    birth(device, p.metrics || [], 'DBIRTH');
    for (const m of metrics)
      if ((m.name.startsWith('Cage/') && m.name !== 'Cage/Seq' && m.type === 'Double') && !m.units)
        err(`DBIRTH ${device}: '${m.name}' without units (engUnit)`);
    return;
  }
  if (type === 'DDATA' || type === 'NDATA') {
    const table = born.get(device);
    if (!table) { err(`${topic} before its birth`); return; }
    for (const m of metrics) {
      const b = table.get(m.alias);
      if (!b) err(`${topic}: alias ${m.alias} not in the birth`);
      else if (m.type && b.type !== m.type) err(`${topic}: alias ${m.alias} (${b.name}) is ${m.type}, born ${b.type}`);
    }
  }
});

function send(topic, metrics) {
  const payload = sparkplug.encodePayload({ timestamp: Date.now(), metrics });
  client.publish(topic, payload, { qos: 1 });
}

function run(line) {
  const [cmd, ...rest] = line.split(' ');
  const tail = (n) => rest.slice(n).join(' ');
  if (cmd === 'dcmd') send(`spBv1.0/${group}/DCMD/${edge}/${rest[0]}`, JSON.parse(tail(1)));
  else if (cmd === 'ncmd') send(`spBv1.0/${group}/NCMD/${edge}`, JSON.parse(tail(0)));
  else if (cmd === 'state')  // a primary host's STATE (Sparkplug 3.0), retained
    client.publish(`spBv1.0/STATE/${rest[0]}`, JSON.stringify({ online: rest[1] === 'true', timestamp: +rest[2] }),
                   { qos: 1, retain: true });
  else if (cmd === 'raw') client.publish(rest[0], Buffer.from(rest[1] || '', 'hex'), { qos: 1 });
  else if (cmd === 'flood') {
    const n = +rest[1], rate = +rest[2], metrics = JSON.parse(tail(3));
    let sent = 0;
    const start = Date.now();
    const tick = () => {
      const due = Math.min(n, Math.floor((Date.now() - start) * rate / 1000) + 1);
      while (sent < due) { send(`spBv1.0/${group}/DCMD/${edge}/${rest[0]}`, metrics); ++sent; }
      if (sent < n) setTimeout(tick, 5); else console.log('FLOODED ' + n);
    };
    tick();
  } else if (cmd === 'report') console.log('REPORT ' + JSON.stringify({ errors, counts, birthBdSeq }));
  else if (cmd === 'quit') { client.end(true, () => process.exit(0)); }
}

let offset = 0;
setInterval(() => {
  let text = '';
  try { text = fs.readFileSync(cmdFile, 'utf8'); } catch (e) { return; }
  if (text.length <= offset) return;
  const chunk = text.slice(offset);
  const last = chunk.lastIndexOf('\n');
  if (last < 0) return;
  offset += last + 1;
  for (const line of chunk.slice(0, last).split('\n')) if (line.trim()) run(line.trim());
}, 20);
