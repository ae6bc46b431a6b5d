// The client's view of the server (server.js): `rcsc lsp` is used only
// when it answers `rcsc lsp --help`; a missing rcsc, or one without the
// `lsp` command, leaves the extension highlighting only.

'use strict';

const test = require('node:test');
const assert = require('node:assert/strict');
const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');
const { probeServer, serverOptions } = require('../server');

/** A fake `rcsc` that exits with `code` for `lsp --help`. */
function fakeRcsc(code) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'rcs-vscode-'));
  const file = path.join(dir, 'rcsc');
  fs.writeFileSync(file, `#!/bin/sh\n[ "$1" = lsp ] && exit ${code}\nexit 3\n`, { mode: 0o755 });
  return file;
}

test('an rcsc that has `lsp` is used', { skip: process.platform === 'win32' }, () => {
  assert.deepEqual(probeServer(fakeRcsc(0)), { ok: true });
});

test('an rcsc without `lsp` (clap exits 2) is not used, with the reason', { skip: process.platform === 'win32' }, () => {
  const probe = probeServer(fakeRcsc(2));
  assert.equal(probe.ok, false);
  assert.match(probe.reason, /lsp` is not available/);
});

test('a missing rcsc is not used, and the setting to change is named', () => {
  const probe = probeServer(path.join(os.tmpdir(), 'no-such-dir-rcs', 'rcsc'));
  assert.equal(probe.ok, false);
  assert.match(probe.reason, /not found \(set rcs\.server\.path\)/);
});

test('the server is `rcsc lsp` over stdio', () => {
  assert.deepEqual(serverOptions('/opt/rcsc'), { command: '/opt/rcsc', args: ['lsp'], transport: 0 });
});
