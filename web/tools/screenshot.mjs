// A screenshot of a running preview, once its model is drawn:
//   node tools/screenshot.mjs http://127.0.0.1:8417/ out.png
import { launchBrowser } from '../tests/harness.mjs';

const [url, out] = process.argv.slice(2);
const browser = await launchBrowser();
try {
  const page = await browser.context.newPage();
  page.on('pageerror', (e) => console.error('page error:', e));
  await page.goto(url);
  await page.waitForFunction(() => window.cgaPreview.modelVersion > 0, null, { timeout: 120000 });
  await page.waitForTimeout(500); // textures
  await page.screenshot({ path: out });
  console.log(JSON.stringify(await page.evaluate(() => ({ stats: window.cgaPreview.stats, drawMs: window.cgaPreview.drawMs }))));
} finally {
  await browser.close();
}
