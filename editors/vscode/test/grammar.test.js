// The TextMate grammar tokenizes CGA as VS Code will: keywords,
// operations, built-in functions, rule names, strings, numbers, comments
// and annotations get their scopes.
const { test } = require("node:test");
const assert = require("node:assert");
const fs = require("node:fs");
const path = require("node:path");
const vsctm = require("vscode-textmate");
const oniguruma = require("vscode-oniguruma");

const grammarPath = path.join(__dirname, "..", "syntaxes", "cga.tmLanguage.json");
const wasm = fs.readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm"));
const onigLib = oniguruma.loadWASM(new Uint8Array(wasm).buffer).then(() => ({
  createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
  createOnigString: (s) => new oniguruma.OnigString(s),
}));
const registry = new vsctm.Registry({
  onigLib,
  loadGrammar: async (scope) =>
    scope === "source.cga"
      ? vsctm.parseRawGrammar(fs.readFileSync(grammarPath, "utf8"), grammarPath)
      : null,
});

async function tokenize(text) {
  const grammar = await registry.loadGrammar("source.cga");
  let state = vsctm.INITIAL;
  const out = [];
  for (const line of text.split("\n")) {
    const r = grammar.tokenizeLine(line, state);
    for (const t of r.tokens) {
      out.push({ text: line.slice(t.startIndex, t.endIndex), scopes: t.scopes });
    }
    state = r.ruleStack;
  }
  return out;
}

/** The innermost scope of the `nth` token whose text is `text`. */
function scope(tokens, text, nth = 0) {
  const found = tokens.filter((t) => t.text === text);
  assert.ok(found.length > nth, `a token "${text}" in ${JSON.stringify(tokens.map((t) => t.text))}`);
  return found[nth].scopes[found[nth].scopes.length - 1];
}

const SAMPLE = `version "2023.0"
import facade : "facade.cga"

/* The lot's
   height. */
@Range(min=3, max=60) @Group("Massing")
attr height = 10.5
const k = 2e3 # a constant
// Start here.
Lot --> extrude(height) comp(f) { top : Roof. | side : facade.Facade }
Roof(h) --> case scope.sx > 20 : roofHip(30) else : t(0, rand(1, 2), 0) NIL
`;

test("keywords, operations and functions", async () => {
  const t = await tokenize(SAMPLE);
  assert.strictEqual(scope(t, "version"), "keyword.control.import.cga");
  assert.strictEqual(scope(t, "import"), "keyword.control.import.cga");
  assert.strictEqual(scope(t, "attr"), "storage.type.cga");
  assert.strictEqual(scope(t, "const"), "storage.type.cga");
  assert.strictEqual(scope(t, "case"), "keyword.control.cga");
  assert.strictEqual(scope(t, "else"), "keyword.control.cga");
  assert.strictEqual(scope(t, "NIL"), "constant.language.cga");
  assert.strictEqual(scope(t, "extrude"), "support.function.operation.cga");
  assert.strictEqual(scope(t, "comp"), "support.function.operation.cga");
  assert.strictEqual(scope(t, "roofHip"), "support.function.operation.cga");
  assert.strictEqual(scope(t, "t"), "support.function.operation.cga");
  assert.strictEqual(scope(t, "rand"), "support.function.builtin.cga");
  assert.strictEqual(scope(t, "scope.sx"), "variable.language.shape.cga");
  assert.strictEqual(scope(t, "Lot"), "entity.name.function.rule.cga");
  assert.strictEqual(scope(t, "Roof"), "entity.name.function.rule.cga");
  assert.strictEqual(scope(t, "-->"), "keyword.operator.rule.cga");
});

test("strings, numbers, comments and annotations", async () => {
  const t = await tokenize(SAMPLE);
  assert.strictEqual(scope(t, "facade.cga"), "string.quoted.double.cga");
  assert.strictEqual(scope(t, "2023.0"), "string.quoted.double.cga");
  assert.strictEqual(scope(t, "10.5"), "constant.numeric.cga");
  assert.strictEqual(scope(t, "2e3"), "constant.numeric.cga");
  assert.strictEqual(scope(t, "30"), "constant.numeric.cga");
  assert.strictEqual(scope(t, "# a constant"), "comment.line.number-sign.cga");
  assert.strictEqual(scope(t, "// Start here."), "comment.line.double-slash.cga");
  assert.strictEqual(scope(t, " The lot's"), "comment.block.cga");
  assert.strictEqual(scope(t, "   height. "), "comment.block.cga");
  assert.strictEqual(scope(t, "Range"), "storage.type.annotation.cga");
  assert.strictEqual(scope(t, "@", 0), "punctuation.definition.annotation.cga");
  assert.strictEqual(scope(t, "Group"), "storage.type.annotation.cga");
  // Names of the user are plain source (the server colours them).
  assert.strictEqual(scope(t, " height = "), "source.cga");
});

test("every sample file of the repository tokenizes", async () => {
  const root = path.join(__dirname, "..", "..", "..", "examples");
  for (const name of fs.readdirSync(root).filter((n) => n.endsWith(".cga"))) {
    const t = await tokenize(fs.readFileSync(path.join(root, name), "utf8"));
    assert.ok(t.some((x) => x.scopes.includes("support.function.operation.cga")), name);
  }
});
