// Opens the bundled Neuroglancer page (index.html, built by build_viewer.sh) at each of a list of
// URLs whose hash holds a viewer state, in headless Chromium (Debian's /usr/bin/chromium, or
// $CHROMIUM) with software WebGL (SwiftShader), and for each waits until the viewer has loaded
// and drawn every visible layer's chunks: viewer.isReady() true on every poll over `settle` ms.
// Then it saves a screenshot of the 3-D panel. It prints one JSON list, one entry per URL:
// whether the viewer got ready, the time it took, the console messages, uncaught page errors,
// failed requests (and those the viewer cancelled), Neuroglancer's own error messages (layers' and the status box's) and the
// WebGL renderer, and when the page was opened and closed. tests/browser/test_neuroglancer.py writes the list of jobs and reads the
// answer.
//
//   node open_viewer.mjs JOBS.json      JOBS.json: [{"url": ..., "screenshot": "x.png"}, ...]
//                                       ($VIEWER_TIMEOUT_MS per page, default 30000)
import { readFileSync } from "node:fs";
import { chromium } from "playwright-core";

const [jobsFile] = process.argv.slice(2);
if (!jobsFile) {
  console.error("usage: node open_viewer.mjs JOBS.json");
  process.exit(2);
}
const jobs = JSON.parse(readFileSync(jobsFile, "utf8"));
const timeout = Number(process.env.VIEWER_TIMEOUT_MS ?? 30000);
const settle = 1000;
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  headless: true,
  args: [
    // WebGL 2 without a GPU: SwiftShader, which Chromium only falls back to when told to.
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
    // The machines reach no network but the package registries: no background connections.
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
    "--no-sandbox",  // CI runs as root
  ],
});
// A console message that reports an error: console.error, or a message saying "error" (the
// chunk workers report a chunk that fails to load or decode with console.log).
const isError = (m) => m.type === "error" || /\berror\b/i.test(m.text);

async function open({ url, screenshot }) {
  const result = {
    url,
    startedAt: Date.now(),  // ms since the epoch, as the test's server log
    endedAt: null,
    ready: false,
    seconds: 0,
    console: [],
    pageErrors: [],
    failedRequests: [],
    abortedRequests: [],
    statusErrors: [],
    renderer: null,
  };
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  page.on("console", (m) => result.console.push({ type: m.type(), text: m.text() }));
  page.on("pageerror", (e) => result.pageErrors.push(String(e)));
  // A request Neuroglancer cancels itself (a fragment of a level of detail it no longer wants,
  // as the panel takes its size) fails with net::ERR_ABORTED: listed apart, not a failure.
  page.on("requestfailed", (r) => {
    const error = r.failure()?.errorText;
    (error === "net::ERR_ABORTED" ? result.abortedRequests : result.failedRequests).push(`${r.url()}: ${error}`);
  });
  page.on("response", (r) => {
    if (r.status() >= 400) result.failedRequests.push(`${r.url()}: HTTP ${r.status()}`);
  });
  try {
    const start = Date.now();
    await page.goto(url, { waitUntil: "load", timeout });
    await page.waitForFunction(() => window.viewer !== undefined, null, { timeout });
    // Ready, or failed: a page that reports an error is given `settle` ms more (for the
    // messages that follow) and then left, rather than waited on until the timeout.
    let readySince = null;
    let failedSince = null;
    while (Date.now() - start < timeout) {
      const ready = await page.evaluate(() => window.viewer.isReady());
      const now = Date.now();
      const failed =
        result.pageErrors.length > 0 ||
        result.failedRequests.length > 0 ||
        result.console.some(isError) ||
        (await page.evaluate(() =>
          window.viewer.layerManager.managedLayers.some((managed) =>
            managed.layer?.dataSources.some((source) => source.loadState?.error !== undefined),
          ),
        ));
      if (failed && failedSince === null) failedSince = now;
      if (failedSince !== null && now - failedSince >= settle) break;
      if (!ready) readySince = null;
      else if (readySince === null) readySince = now;
      else if (now - readySince >= settle) {
        result.ready = true;
        break;
      }
      await page.waitForTimeout(100);
    }
    result.seconds = (Date.now() - start) / 1000;
    result.renderer = await page.evaluate(() => {
      const gl = document.createElement("canvas").getContext("webgl2");
      const info = gl?.getExtension("WEBGL_debug_renderer_info");
      return gl ? gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER) : null;
    });
    // Neuroglancer reports a data source that fails, or a layer's errors, in the layer's own
    // messages and in its status box, not always on the console.
    result.statusErrors = await page.evaluate(() => {
      const errors = [];
      for (const managed of window.viewer.layerManager.managedLayers) {
        const layer = managed.layer;
        if (!layer) continue;
        for (const source of layer.dataSources) {
          const error = source.loadState?.error;
          if (error !== undefined) errors.push(`${managed.name}: ${error.message ?? error}`);
        }
        for (const m of layer.messages) if (m.severity === 2) errors.push(`${managed.name}: ${m.message}`);
      }
      for (const li of document.querySelectorAll("#neuroglancer-status-container li")) {
        const text = li.textContent.trim();
        if (li.style.display !== "none" && text) errors.push(`status: ${text}`);
      }
      return errors;
    });
    const panels = page.locator(".neuroglancer-rendered-data-panel");
    const count = await panels.count();
    if (count !== 1) throw new Error(`expected one 3-D panel, found ${count}`);
    await panels.first().screenshot({ path: screenshot });
  } catch (e) {
    result.pageErrors.push(`driver: ${e}`);
  } finally {
    await page.close();
    result.endedAt = Date.now();
  }
  return result;
}

const results = [];
try {
  for (const job of jobs) results.push(await open(job));
} finally {
  await browser.close();
}
console.log(JSON.stringify(results));
