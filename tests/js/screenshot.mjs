// A picture of a viewer page in headless Chromium, for the docs:
//   node screenshot.mjs PAGE.html 'FRAGMENT' OUT.png [WIDTH HEIGHT [X,Y]]
// X,Y: a click there first (the panel then names the atom under it).
// e.g. node tests/js/screenshot.mjs morph.html 't=0.37&colour=age' docs/images/viewer-morph.png 720 450
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';

const { chromium } = createRequire(import.meta.url)('playwright-core');
const [page, fragment, out, width = '720', height = '450', click] = process.argv.slice(2);
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'skinmesh-chromium-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: '/usr/bin/chromium', headless: true, viewport: { width: Number(width), height: Number(height) },
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
         '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader'],
});
try {
  const tab = await context.newPage();
  await tab.goto(`${pathToFileURL(path.resolve(page)).href}#${fragment}`);
  await tab.waitForFunction(() => document.body.dataset.ready === '1' || document.body.dataset.error);
  const error = await tab.evaluate(() => document.body.dataset.error);
  if (error) throw new Error(error);
  if (click) await tab.mouse.click(...click.split(',').map(Number));
  await tab.evaluate(() => window.skinmeshViewer.drawNow());
  await tab.screenshot({ path: out });
} finally {
  await context.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
