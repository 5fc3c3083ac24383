# SPDX-License-Identifier: Apache-2.0
"""ccomm-web: live view of a node's signals.

A Foxglove WebSocket server (Foxglove, Lichtblick and any ws-protocol client connect to
it; one JSON channel per signal) and a self-contained page that plots chosen signals
with their freshness and loss. Run it as `ccomm web` or `ccomm-web`; see
docs/integrations/liveview.md. Needs the `web` extra (foxglove-sdk)."""
