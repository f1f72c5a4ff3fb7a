// Load each page given on the command line in headless Chromium (Debian's /usr/bin/chromium,
// driven by playwright-core) and check what a person would see: no console error or page
// error, every <img> loaded with a natural size above 0, and at least one table.
// Usage: node check_pages.mjs PAGE.html [PAGE.html ...]; exit 1 on the first page that fails.
import { chromium } from 'playwright-core';
import { pathToFileURL } from 'node:url';
import path from 'node:path';

const pages = process.argv.slice(2);
if (pages.length === 0) {
  console.error('usage: node check_pages.mjs PAGE.html ...');
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--no-first-run'],
});
let failed = 0;
let passed = 0;
for (const file of pages) {
  const page = await browser.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()}`));
  await page.goto(pathToFileURL(path.resolve(file)).href, { waitUntil: 'load' });
  const facts = await page.evaluate(() => ({
    images: [...document.images].map((i) => ({ src: i.getAttribute('src'), ok: i.complete, w: i.naturalWidth, h: i.naturalHeight })),
    tables: document.querySelectorAll('table').length,
    rows: document.querySelectorAll('table tbody tr').length,
  }));
  const bad = facts.images.filter((i) => !i.ok || i.w === 0 || i.h === 0);
  for (const b of bad) errors.push(`figure not rendered: ${b.src} (${b.w}x${b.h})`);
  if (facts.images.length === 0) errors.push('no figure on the page');
  if (facts.tables === 0 || facts.rows === 0) errors.push('no table rows on the page');
  if (errors.length) {
    failed += 1;
    console.log(`FAIL ${file}\n  ${errors.join('\n  ')}`);
  } else {
    passed += 1;
    console.log(`ok   ${file}: ${facts.images.length} figures, ${facts.tables} tables, ${facts.rows} rows`);
  }
  await page.close();
}
await browser.close();
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
