// Starts `scnc lsp` for .scn files; everything else comes from the server.
const vscode = require("vscode");
const { LanguageClient } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const command = vscode.workspace.getConfiguration("scn").get("server.path") || "scnc";
  const server = { command, args: ["lsp"] };
  client = new LanguageClient("scn", "scn language server", server, {
    documentSelector: [
      { scheme: "file", language: "scn" },
      { scheme: "untitled", language: "scn" },
    ],
  });
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
