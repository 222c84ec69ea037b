#!/usr/bin/env bash
# CI for the editor support (issue 18). The language server's Rust tests
# (crates/cga-lsp, and crates/cga-cli/tests/it/lsp.rs driving `cga lsp`
# over stdio) run with `cargo test --workspace`; this script tests what
# cargo does not: the VS Code extension's TextMate grammar (tokenized with
# vscode-textmate + vscode-oniguruma under node's test runner), and that
# the extension packages into a .vsix. Needs node and npm (from the
# registries); installs the extension's locked dependencies.
set -euo pipefail
cd "$(dirname "$0")/../editors/vscode"
npm ci --no-audit --no-fund
npm test
npm run package
test -s cga.vsix
