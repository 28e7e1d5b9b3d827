// node page.mjs URL SCREENSHOT.png: opens the live view's page (http://ADDRESS:PORT/) in Debian's
// Chromium with playwright-core while a run goes on; waits until it shows a camera frame with the
// method's overlay, the state and a plot with data; takes the screenshot; and fails on any console
// error, failed request or HTTP error, and when the pictures are empty.
import { chromium } from "playwright-core";

const [url, screenshot] = process.argv.slice(2);
const problems = [];
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || "/usr/bin/chromium", args: ["--no-sandbox"] });
const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
page.on("console", (m) => { if (m.type() === "error" || m.type() === "warning") problems.push(`console ${m.type()}: ${m.text()}`); });
page.on("pageerror", (e) => problems.push(`page error: ${e.message}`));
page.on("requestfailed", (r) => problems.push(`request failed: ${r.url()} ${r.failure()?.errorText}`));
page.on("response", (r) => { if (r.status() >= 400) problems.push(`HTTP ${r.status()}: ${r.url()}`); });
const requests = [];
page.on("request", (r) => requests.push(r.url()));
await page.goto(url);
let shown = null;
try {
  await page.waitForFunction(() => {
    const debug = document.getElementById("debug");
    const state = document.getElementById("state").textContent;
    return debug.naturalWidth > 0 && document.getElementById("camera").naturalWidth > 0 &&
      state !== "-" && document.getElementById("legend").textContent.includes("s shown");
  }, null, { timeout: 20000 });
  await page.waitForTimeout(1500);  // a few seconds of plot
  // What the pictures hold: coloured pixels in the debug picture (the overlay: the camera is grey)
  // and in the plot and the map (their lines).
  shown = await page.evaluate(async () => {
    // An image being replaced by the next frame has no size for a moment: wait for a loaded one.
    const loaded = async (img) => {
      for (let i = 0; i < 100 && !(img.complete && img.naturalWidth > 0); i++)
        await new Promise((r) => setTimeout(r, 20));
      return img;
    };
    const coloured = (source, w, h) => {
      const c = document.createElement("canvas");
      c.width = w; c.height = h;
      const g = c.getContext("2d");
      g.drawImage(source, 0, 0, w, h);
      const d = g.getImageData(0, 0, w, h).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        const [r, gr, b, a] = [d[i], d[i + 1], d[i + 2], d[i + 3]];
        if (a > 0 && Math.max(r, gr, b) - Math.min(r, gr, b) > 60) n += 1;
      }
      return n;
    };
    const debug = await loaded(document.getElementById("debug"));
    return {
      state: document.getElementById("state").textContent,
      debug_size: [debug.naturalWidth, debug.naturalHeight],
      debug_coloured: coloured(debug, debug.naturalWidth, debug.naturalHeight),
      plot_coloured: coloured(document.getElementById("plot"), 640, 220),
      map_coloured: coloured(document.getElementById("map"), 640, 320),
    };
  });
  await page.screenshot({ path: screenshot, fullPage: true });
} catch (e) {
  problems.push(`the page never showed the run: ${e.message.split("\n")[0]}`);
}
await browser.close();
const elsewhere = requests.filter((u) => !u.startsWith(url) && !u.startsWith("blob:") && !u.startsWith("data:"));
if (elsewhere.length) problems.push(`requests elsewhere: ${elsewhere.slice(0, 3)}`);
if (shown) {
  if (shown.debug_coloured < 50) problems.push(`the debug picture has no overlay (${shown.debug_coloured} coloured pixels)`);
  if (shown.plot_coloured < 100) problems.push(`the plot is empty (${shown.plot_coloured} coloured pixels)`);
  if (shown.map_coloured < 20) problems.push(`the map is empty (${shown.map_coloured} coloured pixels)`);
}
console.log(JSON.stringify({ shown, problems }));
process.exit(problems.length ? 1 : 0);
