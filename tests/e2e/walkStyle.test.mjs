// Walking styles in the page (issue 39): a model trained with styles (the style generator; found by the `styles`
// of its models() entry among the models Random walk offers, never by its id) gets a style selector in Random walk,
// Path and Steer; the chosen style is in the link and in the element's `motion-style` attribute and property, both
// ways; window.playground's generate, followPath and simulateControl take `style` for it and refuse it, with a
// short reason, for a model without styles; an unknown style is refused and the scene kept. Run with
// `node --test tests/e2e/walkStyle.test.mjs`.
import assert from 'node:assert/strict';
import { describe, test } from 'node:test';
import { apiFailure, openPlayground, usePlayground, waitUntil } from './harness.mjs';

/**
 * In the page: the first model Random walk offers whose models() entry lists styles (and a walking model without
 * styles, for the refusals), with the walk picker's label of it.
 */
async function styledWalker(page) {
  const found = await waitUntil(
    page,
    () => {
      const picker = $ui('walk-model');
      const offered = [...(picker?.options ?? [])].map((o) => o.value).filter(Boolean);
      if (!offered.length) return null;
      const models = window.playground.models();
      const styled = models.find((m) => m.styles?.length && offered.includes(m.id));
      const plain = offered.find((id) => !models.find((m) => m.id === id)?.styles?.length);
      if (!styled) return { missing: offered };
      return { id: styled.id, styles: styled.styles, commercial: styled.commercial, plain, label: [...picker.options].find((o) => o.value === styled.id).textContent };
    },
    null,
    { message: 'Random walk lists its models' },
  );
  assert.ok(!found.missing, `public/models/index.json lists no walking model with styles (Random walk offers ${found.missing?.join(', ')})`);
  assert.ok(found.styles.length >= 2, 'a style model has at least two styles');
  return found;
}

describe('walking styles', () => {
  const suite = usePlayground();

  test('models() lists the styles; generate, followPath and simulateControl take style for the style model and refuse it for others', async () => {
    const { page } = suite;
    await page.evaluate(() => window.playground.ready);
    const m = await styledWalker(page);
    assert.equal(m.commercial, false, 'the style model is trained on non-commercial data');
    assert.match(m.label, /\(non-commercial\)$/, 'the picker says so');
    const [first, second, third] = m.styles;

    const made = await page.evaluate(async ({ id, style }) => {
      const g = await window.playground.generate({ model: id, frames: 45, seed: 1, style });
      window.playground.show(g, 'styled.bvh');
      return { frames: g.frames, finite: g.positions.every(Number.isFinite) };
    }, { id: m.id, style: second });
    assert.deepEqual(made, { frames: 45, finite: true });

    const points = [[0, 0], [2.5, 0]];
    const refusals = [
      [apiFailure(page, 'followPath', { points, style: second }), /^followPath: style is not an option of model "[^"]+": it has no styles; leave it out$/],
      [apiFailure(page, 'followPath', { model: m.id, points, style: 'no-such-style' }), new RegExp(`^followPath: unknown style "no-such-style" for model "${m.id}" \\(styles: ${m.styles.join(', ')}\\)$`)],
      [apiFailure(page, 'simulateControl', { model: m.plain, seconds: 1, schedule: [{ t: 0, speed: 1.2, heading: 0 }], style: first }), /^simulateControl: style is not an option of model "[^"]+": it has no styles/],
      [apiFailure(page, 'simulateControl', { model: m.id, seconds: 1, schedule: [{ t: 0, speed: 1.2, heading: 0 }], style: 7 }), /^simulateControl: unknown style 7 for model/],
      [apiFailure(page, 'generate', { model: m.plain, frames: 10, seed: 0, style: first }), /^generate: style is not an option of model/],
    ];
    for (const [failure, pattern] of refusals) {
      const r = await failure;
      assert.match(r.message ?? 'it resolved', pattern);
      assert.equal(r.shown, 45, 'the scene is kept');
    }

    const walked = await page.evaluate(async ({ id, style, points }) => {
      const path = await window.playground.followPath({ model: id, points, style, seed: 1 });
      const run = await window.playground.simulateControl({ model: id, style, seconds: 1, schedule: [{ t: 0, speed: 1.2, heading: 0 }] });
      return { path: path.frames > 10 && path.stats.arcProgress > 0.8, run: run.frames, finite: run.positions.every(Number.isFinite) };
    }, { id: m.id, style: third, points });
    assert.deepEqual(walked, { path: true, run: 30, finite: true });
  });

  test('Random walk: the selector shows for the style model, its choice is in the link and the element, both ways; an unknown style is refused', async () => {
    const { context, page, problems } = await openPlayground(suite.browser, `${suite.url}?mode=walk`);
    const m = await styledWalker(page);
    assert.equal(await page.evaluate(() => $ui('walk-style-field').hidden), true, 'no selector for a model without styles');
    await page.selectOption('#walk-model', m.id);
    const listed = await waitUntil(page, () => !$ui('walk-style-field').hidden && { styles: [...$ui('walk-style').options].map((o) => o.value), value: $ui('walk-style').value }, null, { message: 'the style selector appears' });
    assert.deepEqual(listed, { styles: m.styles, value: m.styles[0] }, "the model's styles, its first chosen");
    await waitUntil(page, () => Number($ui('walk-status').dataset.frame) > 0, null, { message: 'the style model walks' });

    // From the keyboard: focus the selector and step to the next style.
    await page.focus('#walk-style');
    await page.keyboard.press('ArrowDown');
    await waitUntil(page, (s) => $ui('walk-style').value === s, m.styles[1], { message: 'the arrow key chooses the next style' });

    // UI → link, attribute and property; the running walk switches (blended in the worker) and says so.
    await page.selectOption('#walk-style', m.styles[2]);
    const reflected = await waitUntil(
      page,
      ({ id, style }) => {
        const el = document.querySelector('motion-playground');
        const q = new URLSearchParams(location.search);
        return q.get('style') === style && q.get('model') === id && el.getAttribute('motion-style') === style && { property: el.motionStyle, link: location.search, status: $ui('walk-status').textContent };
      },
      { id: m.id, style: m.styles[2] },
      { message: 'the link and the attribute carry the style' },
    );
    assert.equal(reflected.property, m.styles[2]);
    await waitUntil(page, (s) => $ui('walk-status').textContent.includes(`style ${s}`), m.styles[2], { message: 'the walk goes on in the new style' });

    // Attribute and property → UI; an unknown one fires error and keeps the style and the walk.
    const back = await page.evaluate(async (styles) => {
      const el = document.querySelector('motion-playground');
      const until = async (ok, ms = 10_000) => {
        for (const t0 = performance.now(); !ok() && performance.now() - t0 < ms; ) await new Promise((resolve) => setTimeout(resolve, 20));
        return ok();
      };
      const errors = [];
      el.addEventListener('error', (e) => errors.push(e.detail.reason));
      el.setAttribute('motion-style', styles[3] ?? styles[0]);
      const byAttribute = await until(() => $ui('walk-style').value === (styles[3] ?? styles[0]));
      el.motionStyle = styles[1];
      const byProperty = await until(() => $ui('walk-style').value === styles[1]);
      const frame = Number($ui('walk-status').dataset.frame);
      el.setAttribute('motion-style', 'no-such-style');
      await until(() => errors.length > 0);
      const walking = await until(() => Number($ui('walk-status').dataset.frame) > frame + 5);
      return { byAttribute, byProperty, errors, kept: $ui('walk-style').value, walking, mode: el.view.mode };
    }, m.styles);
    assert.equal(back.byAttribute, true, 'the attribute sets the selector');
    assert.equal(back.byProperty, true, 'the property sets the selector');
    assert.equal(back.errors.length, 1, JSON.stringify(back.errors));
    assert.match(back.errors[0], new RegExp(`^style="no-such-style": ${m.id} walks ${m.styles.join(', ')}$`));
    assert.equal(back.kept, m.styles[1], 'the style shown is kept');
    assert.equal(back.walking, true, 'the walk goes on');
    assert.equal(back.mode, 'walk');
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('a link with a style opens Random walk, Steer and Path in it', async () => {
    const { page: probe } = suite;
    const m = await styledWalker(probe);
    const style = m.styles.at(-1);
    for (const mode of ['walk', 'steer', 'path']) {
      // refine=true (the first visit's default) cannot hold for a model without a refiner: it is turned off, no error.
      const { context, page, problems } = await openPlayground(suite.browser, `${suite.url}?mode=${mode}&model=${m.id}&style=${style}${mode === 'walk' ? '&refine=true' : ''}`);
      const shown = await waitUntil(
        page,
        (mode) => !$ui(`${mode}-style-field`).hidden && $ui(`${mode}-style`).options.length > 1 && { value: $ui(`${mode}-style`).value, model: $ui(`${mode}-model`).value },
        mode,
        { message: `${mode}'s style selector shows the link's style` },
      );
      assert.deepEqual(shown, { value: style, model: m.id });
      if (mode !== 'path') await waitUntil(page, (mode) => Number($ui(`${mode}-status`).dataset.frame) > 10, mode, { message: `${mode} runs the style model` });
      if (mode === 'walk') {
        assert.deepEqual(await page.evaluate(() => ({ disabled: $ui('walk-refine').disabled, checked: $ui('walk-refine').checked, error: window.playground.lastError() })), { disabled: true, checked: false, error: null });
      }
      const link = await waitUntil(page, () => new URLSearchParams(location.search).get('style'), null, { message: 'the link keeps the style' });
      assert.equal(link, style);
      assert.deepEqual(problems, []);
      await context.close();
    }
  });
});
