// Open a glassbench review page from disk in Debian's chromium (headless, through playwright-core),
// wait for <model-viewer> to load the scene, take screenshots (the page, OUT.png, and the viewer
// alone, OUT-viewer.png) and print one JSON report:
// console errors, page errors, failed requests, whether the model loaded, the page's numbers.
// Usage: node web/check_page.mjs DIR/index.html OUT.png [CHROMIUM]
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const [page_path, shot, exe = '/usr/bin/chromium'] = process.argv.slice(2);
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'glassbench-chromium-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: exe, headless: true, viewport: { width: 1200, height: 900 },
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const report = { console_errors: [], page_errors: [], failed_requests: [], loaded: false };
try {
  const page = context.pages()[0] || await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') report.console_errors.push(m.text()); });
  page.on('pageerror', (e) => report.page_errors.push(String(e)));
  page.on('requestfailed', (r) => report.failed_requests.push(r.url()));
  await page.goto(pathToFileURL(path.resolve(page_path)).href);
  report.loaded = await page.evaluate(() => new Promise((resolve) => {
    const mv = document.querySelector('model-viewer');
    if (!mv) return resolve(false);
    if (mv.loaded) return resolve(true);
    mv.addEventListener('load', () => resolve(true), { once: true });
    mv.addEventListener('error', () => resolve(false), { once: true });
    setTimeout(() => resolve(false), 60000);
  }));
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  report.numbers = await page.evaluate(() => JSON.parse(document.getElementById('numbers-json').textContent));
  report.shown = await page.evaluate(() => Object.fromEntries(
    [...document.querySelectorAll('[data-key]')].map((e) => [e.dataset.key, e.dataset.value])));
  report.model_viewer = await page.evaluate(() => customElements.get('model-viewer') !== undefined);
  await page.screenshot({ path: shot, fullPage: true });
  await page.locator('model-viewer').screenshot({ path: shot.replace(/\.png$/, '-viewer.png') });
} finally {
  await context.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
console.log(JSON.stringify(report));
