// The VS Code extension for .rcs files: the TextMate grammar and language
// configuration do the highlighting (package.json contributes them); this
// file starts the language client for `rcsc lsp` over stdio, when that
// server exists. Without it the extension stays a highlighting extension.

'use strict';

const vscode = require('vscode');
const { probeServer, serverOptions } = require('./server');

/** @type {import('vscode-languageclient/node').LanguageClient | undefined} */
let client;

async function activate(context) {
  const config = vscode.workspace.getConfiguration('rcs.server');
  if (!config.get('enabled', true)) {
    return;
  }
  const command = config.get('path', 'rcsc') || 'rcsc';
  const probe = probeServer(command);
  const output = vscode.window.createOutputChannel('RCS');
  context.subscriptions.push(output);
  if (!probe.ok) {
    // Highlighting works regardless; say once why there are no diagnostics.
    output.appendLine(`No language server: ${probe.reason}. Highlighting only.`);
    vscode.window.setStatusBarMessage('RCS: highlighting only (no `rcsc lsp`)', 10000);
    return;
  }
  let LanguageClient;
  try {
    ({ LanguageClient } = require('vscode-languageclient/node'));
  } catch (err) {
    output.appendLine(`vscode-languageclient is not installed (run \`npm install\` in the extension folder): ${err.message}`);
    return;
  }
  client = new LanguageClient(
    'rcs',
    'rcsc language server',
    serverOptions(command),
    {
      documentSelector: [{ scheme: 'file', language: 'rcs' }],
      outputChannel: output,
      synchronize: {
        // Plan sets are folders: a change to any .rcs file or rcs.yaml counts.
        fileEvents: vscode.workspace.createFileSystemWatcher('**/{*.rcs,rcs.yaml}'),
      },
    },
  );
  try {
    await client.start();
  } catch (err) {
    output.appendLine(`rcsc lsp did not start: ${err.message}. Highlighting only.`);
    client = undefined;
  }
}

async function deactivate() {
  if (client) {
    await client.stop();
  }
}

module.exports = { activate, deactivate };
