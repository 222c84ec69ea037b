// The client: starts `cga lsp` for .cga files. Everything the editor shows
// beyond highlighting comes from the server.
const vscode = require("vscode");
const { LanguageClient } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const config = vscode.workspace.getConfiguration("cga");
  const command = config.get("server.path") || "cga";
  const serverOptions = { command, args: ["lsp"] };
  const clientOptions = {
    documentSelector: [{ scheme: "file", language: "cga" }],
    initializationOptions: { workspaces: config.get("workspaces") || [] },
  };
  client = new LanguageClient("cga", "CGA language server", serverOptions, clientOptions);
  client.start();
  context.subscriptions.push({ dispose: () => client && client.stop() });
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
