// Renders a langevin-fem report (index.html) in headless Chromium and checks what a reader
// sees: no console errors, failed requests or broken links; the verdict and the failures
// first; the page of a run under 10 screen heights before anything is expanded; every
// figure loads, with a caption; a `check` report of external data leads with the data's
// description and labels continuum references as such; every run states the smallest
// errors it would have caught. Keeps screenshots as CI artefacts.
//
// Usage: node check-index.mjs --report DIR --expect passed|failed --shots DIR --name NAME
// Chromium: $CHROMIUM or /usr/bin/chromium (Debian's package; `make browser-check`
// installs it). Exit 0 when every check holds, 1 otherwise (each failure printed).
import { chromium } from "playwright-core";
import { existsSync, mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const args = Object.fromEntries(
  process.argv
    .slice(2)
    .reduce((acc, a, i, all) => (a.startsWith("--") ? [...acc, [a.slice(2), all[i + 1]]] : acc), []),
);
for (const key of ["report", "expect", "shots", "name"]) {
  if (!args[key]) {
    console.error(`check-index: missing --${key} (usage: --report DIR --expect passed|failed --shots DIR --name NAME)`);
    process.exit(2);
  }
}
if (!["passed", "failed"].includes(args.expect)) {
  console.error(`check-index: --expect ${args.expect}: expected passed or failed`);
  process.exit(2);
}
const report = resolve(args.report);
const index = join(report, "index.html");
if (!existsSync(index)) {
  console.error(`check-index: ${index} does not exist`);
  process.exit(2);
}
mkdirSync(args.shots, { recursive: true });
const summary = JSON.parse(readFileSync(join(report, "summary.json"), "utf8"));
const VIEWPORT = { width: 1280, height: 900 };
const MAX_SCREENS = 10;

const failures = [];
const fail = (what) => failures.push(what);
const problems = [];

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
  ],
});
const page = await browser.newPage({ viewport: VIEWPORT });
page.on("console", (m) => {
  if (m.type() === "error" || m.type() === "warning") problems.push(`console ${m.type()}: ${m.text()}`);
});
page.on("pageerror", (e) => problems.push(`page error: ${e.message}`));
page.on("requestfailed", (r) => problems.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));
page.on("response", (r) => {
  if (r.status() >= 400) problems.push(`HTTP ${r.status()}: ${r.url()}`);
});

await page.goto(pathToFileURL(index).href, { waitUntil: "load" });

// 1. The verdict first, then the failures, then the scenes.
const order = await page.evaluate(() => {
  const top = (sel) => {
    const e = document.querySelector(sel);
    return e ? e.getBoundingClientRect().top + window.scrollY : null;
  };
  return {
    verdict: top("#verdict"),
    failures: top("#failures"),
    scenes: top("#scenes"),
    firstScene: top("section.scene"),
    verdictText: document.querySelector("#verdict")?.innerText ?? "",
    failureRows: [...document.querySelectorAll("#failures table.checks tbody tr.check")].map((r) => r.className),
    noFailureText: document.querySelector("#failures p.ok")?.innerText ?? "",
    sceneRows: document.querySelectorAll("#scenes tbody tr").length,
    sceneSections: document.querySelectorAll("section.scene").length,
    openDetails: document.querySelectorAll("details[open]").length,
    checkTables: document.querySelectorAll("section.scene details.checks").length,
    height: document.documentElement.scrollHeight,
    firstNote: document.querySelector("#scenes tbody tr td.detail")?.innerText ?? "",
    referenceCells: [...document.querySelectorAll("section.scene details.checks table.checks tbody tr.check")].map(
      (r) => r.querySelectorAll("td")[9]?.textContent ?? "",
    ),
    detectable: [...document.querySelectorAll("section.scene details.notes li")]
      .map((li) => li.textContent)
      .filter((t) => t.includes("would have caught")),
  };
});
// A `check` report of external data (issue #31): the data's own description leads; every
// reference that is the continuum's says so in the table; a run whose every reference is
// the continuum's says so in every caption (below); every run states (in its scene's
// notes) the smallest errors it would have caught.
const checked = summary.scenes.length === 1 && (summary.scenes[0].notes[0] ?? "").startsWith("checked data:");
const allChecks = summary.scenes.flatMap((s) => s.checks);
if (checked) {
  if (!order.firstNote.startsWith("checked data:")) fail(`first note: expected the data's description, got "${order.firstNote.slice(0, 80)}"`);
  const continuum = allChecks.filter((c) => c.reference_kind === "continuum" && c.reference !== null).length;
  const marked = order.referenceCells.filter((t) => t.includes("(continuum)")).length;
  if (marked !== continuum) fail(`${marked} reference cells say (continuum), summary.json has ${continuum} continuum references`);
}
const statedRuns = summary.scenes.flatMap((s) => [...new Set(s.detectable.map((d) => d.run))]);
if (order.detectable.length !== statedRuns.length)
  fail(`${order.detectable.length} detectable-deviation notes shown for ${statedRuns.length} runs with one in summary.json`);
const word = args.expect === "passed" ? "PASSED" : "FAILED";
if (!order.verdictText.startsWith(word)) fail(`verdict: expected ${word}, the page says "${order.verdictText.slice(0, 80)}"`);
if (order.verdict === null || order.verdict > VIEWPORT.height / 2) fail(`verdict not in the top half of the first screen (at ${order.verdict} px)`);
if (!(order.failures > order.verdict && order.scenes > order.failures && order.firstScene > order.scenes))
  fail(`order: verdict ${order.verdict}, failures ${order.failures}, scenes ${order.scenes}, first scene ${order.firstScene} px`);
const failedChecks = summary.scenes.flatMap((s) => s.checks.filter((c) => !c.passed));
if (order.failureRows.length !== failedChecks.length)
  fail(`failures table: ${order.failureRows.length} rows, summary.json has ${failedChecks.length} failed checks`);
if (order.failureRows.some((c) => c !== "check fail")) fail("a row of the failures table is not marked failed");
if (args.expect === "passed" && !order.noFailureText.includes("No check failed")) fail("a passing run does not say that no check failed");
if (args.expect === "failed" && failedChecks.length === 0) fail("expected a failing run, summary.json has no failed check");
if (order.sceneRows !== summary.scenes.length || order.sceneSections !== summary.scenes.length)
  fail(`scenes: ${order.sceneRows} table rows and ${order.sceneSections} sections for ${summary.scenes.length} scenes`);
if (order.checkTables !== summary.scenes.filter((s) => s.checks.length > 0).length)
  fail(`${order.checkTables} collapsed check tables for ${summary.scenes.length} scenes`);
if (order.openDetails !== 0) fail(`${order.openDetails} sections are expanded on load (all should be collapsed)`);
const screens = order.height / VIEWPORT.height;
if (screens >= MAX_SCREENS) fail(`page is ${order.height} px tall before expansion: ${screens.toFixed(1)} screen heights (limit ${MAX_SCREENS})`);

await page.screenshot({ path: join(args.shots, `${args.name}-top.png`) });
await page.screenshot({ path: join(args.shots, `${args.name}-collapsed.png`), fullPage: true });

// 2. Links: every relative link names a file of the report; every anchor an id.
const links = await page.evaluate(() =>
  [...document.querySelectorAll("a[href]")].map((a) => a.getAttribute("href")),
);
for (const href of links) {
  if (/^[a-z]+:/i.test(href)) {
    fail(`external link ${href} (the report is self-contained)`);
  } else if (href.startsWith("#")) {
    const ok = await page.evaluate((id) => document.getElementById(id) !== null, href.slice(1));
    if (!ok) fail(`anchor ${href} names no element`);
  } else if (!existsSync(join(report, decodeURIComponent(href)))) {
    fail(`link ${href}: no such file in ${report}`);
  }
}

// 3. Expanded: every figure loads and has a caption.
await page.evaluate(() => document.querySelectorAll("details").forEach((d) => (d.open = true)));
// Wait for the images (at most 20 s: a figure that does not load is reported below).
await page
  .waitForFunction(() => [...document.images].every((i) => i.complete), null, { timeout: 20000 })
  .catch(() => {});
const figures = await page.evaluate(() =>
  [...document.querySelectorAll("figure")].map((f) => {
    const img = f.querySelector("img");
    const cap = f.querySelector("figcaption");
    const code = cap?.querySelector("code")?.innerText ?? "";
    return {
      src: img?.getAttribute("src"),
      loaded: !!img && img.complete && img.naturalWidth > 0,
      caption: (cap?.innerText ?? "").replace(code, "").trim(),
    };
  }),
);
const expectedFigures = summary.scenes.reduce((n, s) => n + s.figures.length, 0);
if (figures.length !== expectedFigures) fail(`${figures.length} figures on the page, summary.json lists ${expectedFigures}`);
for (const f of figures) {
  if (!f.loaded) fail(`figure ${f.src} did not load`);
  if (f.caption.length < 20) fail(`figure ${f.src} has no caption (a caption says what is plotted)`);
}
if (checked && allChecks.length > 0 && allChecks.every((c) => c.reference_kind === "continuum")) {
  for (const f of figures) {
    if (!f.caption.startsWith("References: the continuum")) fail(`figure ${f.src}: a continuum-referenced caption must say so first: "${f.caption.slice(0, 80)}"`);
    if (/discretized|discrete update|discrete process/.test(f.caption)) fail(`figure ${f.src}: its caption speaks of a discrete reference there is none of`);
  }
}
const expandedHeight = await page.evaluate(() => document.documentElement.scrollHeight);
const shown = await page.$$("figure");
for (const [k, f] of shown.slice(0, 3).entries()) {
  await f.scrollIntoViewIfNeeded();
  await f.screenshot({ path: join(args.shots, `${args.name}-figure-${k + 1}.png`) });
}
// A figure on its own, as a reader who follows its link sees it.
if (figures.length > 0) {
  await page.goto(pathToFileURL(join(report, decodeURIComponent(figures[0].src))).href, { waitUntil: "load" });
  await page.screenshot({ path: join(args.shots, `${args.name}-figure-alone.png`) });
}
await browser.close();

for (const p of problems) fail(p);
const result = {
  report,
  expect: args.expect,
  height_px: order.height,
  screen_heights: Number(screens.toFixed(2)),
  expanded_height_px: expandedHeight,
  failures_listed: order.failureRows.length,
  figures: figures.length,
  links: links.length,
  problems: failures,
};
writeFileSync(join(args.shots, `${args.name}.json`), JSON.stringify(result, null, 2) + "\n");
if (failures.length > 0) {
  console.error(`browser check ${args.name}: ${failures.length} problem(s):`);
  for (const f of failures) console.error(`  - ${f}`);
  process.exit(1);
}
console.log(
  `browser check ${args.name}: ${word} shown first, ${order.failureRows.length} failures listed, ` +
    `${screens.toFixed(1)} screen heights collapsed, ${figures.length} figures loaded with captions, ` +
    `${links.length} links resolve; screenshots in ${args.shots}`,
);
