// The TextMate grammar (syntaxes/rcs.tmLanguage.json) as VS Code runs it:
// vscode-textmate with the Oniguruma regex engine. Every regex must compile
// under Oniguruma, and a sample and the repository's plans must get the
// scopes the grammar promises. Run with `npm test` in editors/vscode.

'use strict';

const test = require('node:test');
const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const oniguruma = require('vscode-oniguruma');
const vsctm = require('vscode-textmate');

const GRAMMAR_PATH = path.join(__dirname, '..', 'syntaxes', 'rcs.tmLanguage.json');
const REPO = path.join(__dirname, '..', '..', '..');

const onigLib = (async () => {
  const wasm = fs.readFileSync(require.resolve('vscode-oniguruma/release/onig.wasm'));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  return {
    createOnigScanner: (sources) => new oniguruma.OnigScanner(sources),
    createOnigString: (s) => new oniguruma.OnigString(s),
  };
})();

async function loadGrammar() {
  const registry = new vsctm.Registry({
    onigLib,
    loadGrammar: async (scopeName) => {
      if (scopeName !== 'source.rcs') {
        return null;
      }
      return vsctm.parseRawGrammar(fs.readFileSync(GRAMMAR_PATH, 'utf8'), GRAMMAR_PATH);
    },
  });
  return registry.loadGrammar('source.rcs');
}

/** Tokens of `text` as [{ text, scopes, line }]. */
function tokenize(grammar, text) {
  const tokens = [];
  let state = vsctm.INITIAL;
  text.split('\n').forEach((line, n) => {
    const result = grammar.tokenizeLine(line, state);
    for (const token of result.tokens) {
      tokens.push({ text: line.slice(token.startIndex, token.endIndex), scopes: token.scopes, line: n + 1 });
    }
    state = result.ruleStack;
  });
  return tokens;
}

/** Every regex of the grammar (match, begin, end, while), with where it is. */
function regexes(node, where, out) {
  if (Array.isArray(node)) {
    node.forEach((item, i) => regexes(item, `${where}[${i}]`, out));
  } else if (node && typeof node === 'object') {
    for (const [key, value] of Object.entries(node)) {
      if (['match', 'begin', 'end', 'while'].includes(key) && typeof value === 'string') {
        out.push({ where: `${where}.${key}`, source: value });
      } else {
        regexes(value, `${where}.${key}`, out);
      }
    }
  }
  return out;
}

test('the grammar is JSON with the scope name package.json contributes', () => {
  const grammar = JSON.parse(fs.readFileSync(GRAMMAR_PATH, 'utf8'));
  assert.equal(grammar.scopeName, 'source.rcs');
  const manifest = JSON.parse(fs.readFileSync(path.join(__dirname, '..', 'package.json'), 'utf8'));
  const contributed = manifest.contributes.grammars[0];
  assert.equal(contributed.scopeName, grammar.scopeName);
  assert.equal(path.resolve(__dirname, '..', contributed.path), GRAMMAR_PATH);
  assert.deepEqual(manifest.contributes.languages[0].extensions, ['.rcs']);
  // Every `include` names a repository entry that exists.
  const includes = JSON.stringify(grammar).match(/"include":"#[^"]+"/g) || [];
  for (const include of includes) {
    const name = include.slice('"include":"#'.length, -1);
    assert.ok(grammar.repository[name], `#${name} is included but not defined`);
  }
});

test('every regex of the grammar compiles under Oniguruma', async () => {
  await onigLib;
  const grammar = JSON.parse(fs.readFileSync(GRAMMAR_PATH, 'utf8'));
  const all = regexes(grammar, 'grammar', []);
  assert.ok(all.length > 40, `only ${all.length} regexes found`);
  for (const { where, source } of all) {
    assert.doesNotThrow(() => new oniguruma.OnigScanner([source]), `${where}: ${source}`);
  }
  // The check can fail: an unbalanced group does not compile.
  assert.throws(() => new oniguruma.OnigScanner(['(unclosed']));
});

const SAMPLE = `/// A unit.
#[allow(no_done)]
controller UNIT "Unit" {
    subordinates INFEED, FILLER
    command START accept when state == Idle
    status state: PackState = Idle
    var rpm: f64 = 0.0 // knots
    /* block */
    plan START {
        E0: *0 when new_command && io.stale_time > 50ms -> S1 { INFEED <- START(speed: 1.5) }
        E1: S1 | S2 when abs(rpm) < 0x00FF -> Error(FAULTED) { report ERROR(FAULTED) }
        *2 except S1 otherwise -> same
    }
}
`;

function scopeOf(tokens, text, line) {
  const token = tokens.find((t) => t.text === text && (line === undefined || t.line === line));
  assert.ok(token, `no token \`${text}\`${line ? ` on line ${line}` : ''}: ${JSON.stringify(tokens.map((t) => t.text))}`);
  return token.scopes.join(' ');
}

test('a sample gets the scopes of keywords, comments, labels, states and literals', async () => {
  const grammar = await loadGrammar();
  const tokens = tokenize(grammar, SAMPLE);
  const expect = [
    ['/// A unit.', 'comment.line.documentation.rcs'],
    ['// knots', 'comment.line.double-slash.rcs'],
    ['controller', 'keyword.declaration.controller.rcs'],
    ['UNIT', 'entity.name.type.controller.rcs'],
    ['Unit', 'string.quoted.double.rcs'],
    ['allow', 'entity.other.attribute-name.lint-level.rcs'],
    ['plan', 'keyword.declaration.plan.rcs'],
    ['START', 'entity.name.function.verb.rcs', 9],
    ['E0', 'entity.name.label.row.rcs'],
    ['*0', 'entity.name.label.dont-care.rcs'],
    ['when', 'keyword.control.conditional.rcs', 10],
    ['S1', 'constant.other.state.rcs', 10],
    ['S2', 'constant.other.state.rcs', 11],
    ['new_command', 'variable.language.rcs'],
    ['stale_time', 'variable.other.property.rcs'],
    ['ms', 'keyword.other.unit.rcs'],
    ['<-', 'keyword.operator.send.rcs'],
    ['abs', 'support.function.builtin.rcs'],
    ['0x00FF', 'constant.numeric.hex.rcs'],
    ['Error', 'constant.language.state.error.rcs'],
    ['FAULTED', 'constant.other.error-code.rcs', 11],
    ['report', 'keyword.other.report.rcs'],
    ['except', 'keyword.control.except.rcs'],
    ['otherwise', 'keyword.control.conditional.otherwise.rcs'],
    ['same', 'constant.language.same.rcs'],
    ['f64', 'storage.type.primitive.rcs'],
    ['PackState', 'entity.name.type.rcs'],
  ];
  for (const [text, scope, line] of expect) {
    assert.match(scopeOf(tokens, text, line), new RegExp(`(^| )${scope.replace(/\./g, '\\.')}( |$)`), `\`${text}\``);
  }
  // Every `E0`-style label followed by `:` is a label wherever the row starts.
  assert.match(scopeOf(tokens, 'E1'), /entity\.name\.label\.row\.rcs/);
});

function rcsFiles(dir, out) {
  for (const entry of fs.readdirSync(dir, { withFileTypes: true })) {
    if (entry.name.startsWith('.') || entry.name === 'target' || entry.name === 'node_modules') {
      continue;
    }
    const full = path.join(dir, entry.name);
    if (entry.isDirectory()) {
      rcsFiles(full, out);
    } else if (entry.name.endsWith('.rcs')) {
      out.push(full);
    }
  }
  return out;
}

test('in the shipped plans every row label and `when` is scoped', async () => {
  const grammar = await loadGrammar();
  const files = rcsFiles(path.join(REPO, 'plans'), []);
  assert.ok(files.length >= 10, `only ${files.length} plans found`);
  let labels = 0;
  for (const file of files) {
    const tokens = tokenize(grammar, fs.readFileSync(file, 'utf8'));
    for (const token of tokens) {
      const inComment = token.scopes.some((s) => s.startsWith('comment.'));
      if (inComment) {
        continue;
      }
      if (/^E[0-9]+$/.test(token.text.trim())) {
        labels += 1;
        assert.ok(
          token.scopes.includes('entity.name.label.row.rcs'),
          `${path.relative(REPO, file)}:${token.line}: \`${token.text}\` is ${token.scopes.join(' ')}`,
        );
      }
      if (token.text.trim() === 'when') {
        assert.ok(
          token.scopes.some((s) => s.startsWith('keyword.control')),
          `${path.relative(REPO, file)}:${token.line}: \`when\` is ${token.scopes.join(' ')}`,
        );
      }
    }
  }
  assert.ok(labels > 50, `only ${labels} row labels seen`);
});
