/**
 * axe-core in the page, and the walk of the page's states it checks: the empty state, the demo
 * with the inspector, settings and Bind open, and a replay at its end. The main tier walks them
 * in the dark theme (the default); the slow tier (tests/slow/screenshots.test.ts) in the light.
 */
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import type { Page } from 'playwright-core';
import { type AppSession, demoRunning, openPage, replayToEnd, shot } from './app-fixture.js';

const AXE_SOURCE = readFileSync(createRequire(import.meta.url).resolve('axe-core/axe.min.js'), 'utf8');

/**
 * axe-core's violations of impact serious or critical in `page` (or only inside the elements
 * `include` selects), as "rule: targets" lines; every impact is counted in the log under `label`.
 */
export async function axe(page: Page, label: string, include?: string[]): Promise<string[]> {
  const t0 = Date.now();
  await page.evaluate(AXE_SOURCE);
  const violations = await page.evaluate(async (selectors) => {
    const w = window as unknown as {
      axe: { run(ctx: object, opts: object): Promise<{ violations: { id: string; impact: string; nodes: { target: string[] }[] }[] }> };
    };
    const r = await w.axe.run(selectors === undefined ? document : { include: selectors.map((s) => [s]) }, { resultTypes: ['violations'] });
    return r.violations.map((v) => ({ id: v.id, impact: v.impact, targets: v.nodes.map((n) => n.target.join(' ')) }));
  }, include);
  const byImpact: Record<string, number> = {};
  for (const v of violations) byImpact[v.impact] = (byImpact[v.impact] ?? 0) + v.targets.length;
  console.log(
    `axe ${label} (${Date.now() - t0} ms): ${JSON.stringify(byImpact)} ${violations.map((v) => `${v.id}(${v.impact})`).join(' ')}`,
  );
  return violations
    .filter((v) => v.impact === 'serious' || v.impact === 'critical')
    .map((v) => `${v.id}: ${v.targets.slice(0, 3).join(', ')}`);
}

/** The serious and critical violations of every state of the page in `scheme`; `capture` is replayed. */
export async function axeStates(app: AppSession, scheme: 'light' | 'dark', capture: string): Promise<string[]> {
  const found: string[] = [];
  const empty = await openPage(app, { scheme, query: '?demo=0' });
  await empty.page.getByTestId('empty-state').waitFor();
  found.push(...(await axe(empty.page, `empty ${scheme}`)));
  await empty.page.context().close();

  const demo = await openPage(app, { scheme });
  await demoRunning(demo.page);
  await demo.page.getByRole('button', { name: 'Inspect frames…' }).click();
  await demo.page.locator('.insp-table').waitFor();
  // Paused, the inspector holds its thousand rows still while axe walks them.
  await demo.page.getByRole('button', { name: 'Follow' }).click();
  await demo.page.locator('.counters .help summary').click();
  found.push(...(await axe(demo.page, `demo+inspector ${scheme}`)));
  // Its thousand rows were walked: closed, so the panels after are walked alone.
  await demo.page.getByRole('button', { name: 'Close the inspector' }).click();
  await demo.page.getByRole('button', { name: 'Settings', exact: true }).click();
  await demo.page.getByRole('combobox', { name: 'Resolution' }).waitFor();
  found.push(...(await axe(demo.page, `demo+settings ${scheme}`)));
  await demo.page.keyboard.press('Escape');
  await demo.page.getByRole('button', { name: 'Bind…' }).click();
  await demo.page.locator('.bind').waitFor();
  await demo.page.locator('.bind .technical summary').click();
  found.push(...(await axe(demo.page, `demo+bind ${scheme}`)));
  await shot(demo.page, `ui-bind-1280-${scheme}`);
  await demo.page.context().close();

  const rep = await openPage(app, { scheme, query: '?demo=0' });
  await replayToEnd(rep.page, capture);
  found.push(...(await axe(rep.page, `replay ${scheme}`)));
  await rep.page.context().close();
  return found;
}
