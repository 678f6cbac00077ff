// Drives headless Chromium over the DevTools protocol (node's built-in
// WebSocket, node --experimental-websocket): opens URL, waits for the
// page's #selftest-result and prints it. Real time runs (no virtual time),
// so the page's own clock measures what a user would see.
// Usage: node --experimental-websocket bench/explorer_previews.mjs URL PROFILE_DIR
import {spawn} from 'node:child_process';
import {existsSync, readFileSync} from 'node:fs';
import {join} from 'node:path';

const [url, profile] = process.argv.slice(2);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const browser = spawn('chromium', ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic',
  '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--window-size=1500,950', '--remote-debugging-port=0', '--user-data-dir=' + profile, 'about:blank'],
  {stdio: 'ignore'});
let exitCode = 1;
try {
  const portFile = join(profile, 'DevToolsActivePort');
  for (let i = 0; i < 200 && !existsSync(portFile); ++i) await sleep(100);
  const port = readFileSync(portFile, 'utf8').split('\n')[0];
  const targets = await (await fetch(`http://127.0.0.1:${port}/json/list`)).json();
  const page = targets.find((t) => t.type === 'page');
  const ws = new WebSocket(page.webSocketDebuggerUrl);
  await new Promise((resolve, reject) => { ws.onopen = resolve; ws.onerror = reject; });
  let id = 0;
  const pending = new Map();
  ws.onmessage = (m) => {
    const msg = JSON.parse(m.data);
    if (pending.has(msg.id)) { pending.get(msg.id)(msg); pending.delete(msg.id); }
  };
  const send = (method, params) => new Promise((resolve) => {
    pending.set(++id, resolve);
    ws.send(JSON.stringify({id, method, params}));
  });
  await send('Page.navigate', {url});
  const probe = "(() => { const r = document.getElementById('selftest-result');" +
                " return r && r.dataset.status ? r.textContent : ''; })()";
  let result = '';
  for (let i = 0; i < 1200 && !result; ++i) {
    await sleep(100);
    const r = await send('Runtime.evaluate', {expression: probe, returnByValue: true});
    result = (r.result && r.result.result && r.result.result.value) || '';
  }
  console.log(result || 'selftest failed: no result in 120 s');
  exitCode = result.startsWith('selftest ok') ? 0 : 1;
  ws.close();
} finally {
  browser.kill();
}
process.exit(exitCode);
