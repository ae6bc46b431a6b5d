// Finding the language server (`rcsc lsp`) without VS Code: extension.js
// starts a client only when this says the server is there, so that an
// rcsc without `lsp` (or no rcsc at all) leaves highlighting working and
// shows one quiet message instead of a client failing and restarting.
// Kept apart from extension.js so that test/server.test.js can run it
// under plain Node.

'use strict';

const { spawnSync } = require('node:child_process');

/** How long `rcsc lsp --help` may take before the server counts as absent. */
const PROBE_TIMEOUT_MS = 10000;

/**
 * Asks `command lsp --help` whether the server exists.
 * @param {string} command the rcsc executable (a name on PATH or a path)
 * @returns {{ ok: true } | { ok: false, reason: string }}
 */
function probeServer(command) {
  let result;
  try {
    result = spawnSync(command, ['lsp', '--help'], {
      timeout: PROBE_TIMEOUT_MS,
      stdio: ['ignore', 'ignore', 'pipe'],
      encoding: 'utf8',
      windowsHide: true,
    });
  } catch (err) {
    return { ok: false, reason: `cannot run \`${command}\`: ${err.message}` };
  }
  if (result.error) {
    if (result.error.code === 'ENOENT') {
      return { ok: false, reason: `\`${command}\` was not found (set rcs.server.path)` };
    }
    return { ok: false, reason: `cannot run \`${command}\`: ${result.error.message}` };
  }
  if (result.status !== 0) {
    return {
      ok: false,
      reason: `\`${command} lsp\` is not available in this rcsc (it comes with a later version)`,
    };
  }
  return { ok: true };
}

/**
 * The server options for vscode-languageclient: `rcsc lsp` over stdio.
 * @param {string} command the rcsc executable
 */
function serverOptions(command) {
  return { command, args: ['lsp'], transport: 0 /* TransportKind.stdio */ };
}

module.exports = { probeServer, serverOptions, PROBE_TIMEOUT_MS };
