// The entry of the page's one bundled library: @foxglove/ws-protocol's
// FoxgloveClient (the Foxglove WebSocket protocol client: subprotocol check,
// JSON and binary frame parsing, subscribe/advertise, client message data).
// tools/dash/CMakeLists.txt bundles it with esbuild (npm, package-lock.json)
// into <build>/share/hoist-twin/dash/vendor/foxglove-client.js, an ES module
// that web/app.js imports; nothing is fetched at run time.
//
// The client's own module, not the package index: the index also exports
// FoxgloveServer, whose Node-only dependencies the page does not need.
export { default as FoxgloveClient } from "@foxglove/ws-protocol/dist/esm/src/FoxgloveClient.js";
