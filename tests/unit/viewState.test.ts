import { describe, expect, test } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { parseManifest } from '../../web/model/manifest';
import { Registry } from '../../web/runtime/registry';
import { embedSnippet, modeModels, parseView, parseViewValue, styleAttribute, viewQuery } from '../../web/ui/viewState';
import { checkSourceUrl, fetchMotionSource, MAX_SOURCE_BYTES } from '../../web/runtime/import/motionSource';

describe('view state (attributes and links)', () => {
  test('reads every setting and writes it back the same', () => {
    const q = new URLSearchParams('mode=path&model=vae-lstm&seed=7&path=0,0;4,2.5;8,0');
    const { view, errors } = parseView((k) => q.get(k));
    expect(errors).toEqual([]);
    expect(view).toEqual({ mode: 'path', model: 'vae-lstm', seed: 7, path: [[0, 0], [4, 2.5], [8, 0]] });
    const again = new URLSearchParams(viewQuery(view));
    expect(parseView((k) => again.get(k)).view).toEqual(view);
  });

  test('the look (issue 40): read, written to links and snippets, a bad one refused', () => {
    const q = new URLSearchParams('mode=walk&look=both');
    const { view, errors } = parseView((k) => q.get(k));
    expect(errors).toEqual([]);
    expect(view).toEqual({ mode: 'walk', look: 'both' });
    expect(viewQuery({ mode: 'dance', look: 'skeleton' })).toBe('mode=dance&look=skeleton');
    expect(embedSnippet({ mode: 'walk', look: 'skeleton' }, '/m.js')).toMatch(/<motion-playground mode="walk" look="skeleton" /);
    expect(parseViewValue('look', 'boxes')).toEqual({ error: 'look="boxes": must be one of skeleton, character, both' });
  });

  test('refuses bad values with a reason and keeps the rest', () => {
    const q = new URLSearchParams('mode=fly&seed=-1&temperature=9&refine=maybe&style=<b>x</b>&path=1,2,3');
    const { view, errors } = parseView((k) => q.get(k));
    expect(view).toEqual({});
    expect(errors).toHaveLength(6);
    expect(errors[0]).toMatch(/^mode="fly": must be one of clip, walk, dance, path, steer$/);
    expect(errors.join('\n')).toMatch(/seed="-1": must be a whole number/);
    expect(errors.join('\n')).toMatch(/temperature="9": must be a number from 0 to 1.5/);
    expect(errors.join('\n')).toMatch(/refine="maybe"/);
    expect(errors.join('\n')).toMatch(/style="<b>x<\/b>": must be a style name such as salsa or elderly/);
    expect(errors.join('\n')).toMatch(/path="1,2,3": must be x,z pairs/);
  });

  test('a model the mode does not have is refused (the shipped models, by what their descriptors say they do)', () => {
    const manifest = parseManifest(JSON.parse(readFileSync(resolve(__dirname, '../../public/models/index.json'), 'utf8')));
    const models = modeModels(new Registry(manifest));
    expect(models).toEqual({ clip: [], walk: ['generator', 'style-generator'], dance: ['aclstm-mdn', 'aclstm'], path: ['generator', 'style-generator', 'latent-erd', 'vae-lstm'], steer: ['generator', 'style-generator', 'latent-erd'] });
    const { view, errors } = parseView((k) => ({ mode: 'steer', model: 'vae-lstm' })[k as 'mode'] ?? null, models);
    expect(view).toEqual({ mode: 'steer' });
    expect(errors).toEqual(['model="vae-lstm": steer mode shows generator, style-generator, latent-erd']);
    // A link made before 2026-12-05 may name the vanilla baseline, no longer shipped: said, and Dance opens its default.
    const old = parseView((k) => ({ mode: 'dance', model: 'aclstm-vanilla', style: 'salsa' })[k as 'mode'] ?? null, models);
    expect(old.view).toEqual({ mode: 'dance', style: 'salsa' });
    expect(old.errors).toEqual(['model="aclstm-vanilla": dance mode shows aclstm-mdn, aclstm']);
  });

  test('a path too short or too far is refused by the path rules', () => {
    expect(parseViewValue('path', '0,0')).toMatchObject({ error: expect.stringMatching(/^path="0,0": /) });
    expect(parseViewValue('path', '0,0;99999,0')).toMatchObject({ error: expect.stringMatching(/10000/) });
    expect(parseViewValue('path', 'x'.repeat(5000))).toMatchObject({ error: expect.stringMatching(/too long/) });
  });

  test('the embed snippet escapes what it quotes', () => {
    const s = embedSnippet({ mode: 'dance', style: 'salsa', seed: 3 }, 'https://example.org/a"b/motion-playground.js');
    expect(s).toContain('src="https://example.org/a&quot;b/motion-playground.js"');
    expect(s).toContain('<motion-playground mode="dance" dance-style="salsa" seed="3" autoplay camera-controls controls="minimal"');
    // A walking style (issue 39) goes into motion-style: the element's own style attribute is its inline CSS.
    const walk = embedSnippet({ mode: 'walk', model: 'style-generator', style: 'elderly', seed: 2 }, 'https://example.org/motion-playground.js');
    expect(walk).toContain('<motion-playground mode="walk" model="style-generator" motion-style="elderly" seed="2" ');
    expect(styleAttribute('path')).toBe('motion-style');
    expect(styleAttribute('dance')).toBe('dance-style');
  });
});

describe('the element src fetch', () => {
  const page = 'https://site.example/demo/index.html';
  test('only the page origin or an allowed one, over http(s)', () => {
    expect(checkSourceUrl('clips/a.bvh', page, []).href).toBe('https://site.example/demo/clips/a.bvh');
    expect(() => checkSourceUrl('https://other.example/a.bvh', page, [])).toThrow(/https:\/\/other.example is not this page's origin/);
    expect(checkSourceUrl('https://other.example/a.bvh', page, ['https://other.example']).origin).toBe('https://other.example');
    expect(() => checkSourceUrl('javascript:alert(1)', page, [])).toThrow(/only http\(s\)/);
    expect(() => checkSourceUrl('data:text/plain,HIERARCHY', page, ['data:'])).toThrow(/only http\(s\)/);
  });

  test('reads the text, gunzips, and stops at the size limit', async () => {
    const text = 'HIERARCHY\nROOT Hips\n';
    const plain = await fetchMotionSource('a.bvh', page, [], async () => new Response(text));
    expect(plain).toBe(text);
    const zipped = new Uint8Array(await new Response(new Blob([text]).stream().pipeThrough(new CompressionStream('gzip'))).arrayBuffer());
    expect(await fetchMotionSource('a.bvh.gz', page, [], async () => new Response(zipped))).toBe(text);
    const big = new Response(new Uint8Array(MAX_SOURCE_BYTES + 1));
    await expect(fetchMotionSource('a.bvh', page, [], async () => big)).rejects.toThrow(/larger than the 32 MiB limit/);
    await expect(fetchMotionSource('a.bvh', page, [], async () => new Response('no', { status: 404 }))).rejects.toThrow(/HTTP 404/);
  });
});
