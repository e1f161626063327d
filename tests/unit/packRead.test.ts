// Reading a model pack's files (web/runtime/packs/pack.ts) on the fixture packs (tests/fixtures/packs: 30-iteration
// `python -m training.own` runs, my-walks of --kind locomotion, my-dance of --kind dance on three acLSTM salsa files):
// the registry entry each makes, and the refusals (short, naming the problem).
import { readFileSync, readdirSync } from 'node:fs';
import path from 'node:path';
import { describe, expect, it } from 'vitest';
import { looksLikePack, packFiles, readPack, type PackFile } from '../../web/runtime/packs/pack';
import { Registry } from '../../web/runtime/registry';

const DIR = path.join(__dirname, '..', 'fixtures', 'packs');
const folder = (pack = 'my-walks'): PackFile[] => readdirSync(path.join(DIR, pack)).map((name) => ({ name, bytes: new Uint8Array(readFileSync(path.join(DIR, pack, name))) }));
const json = () => JSON.parse(new TextDecoder().decode(folder().find((f) => f.name === 'my-walks.json')!.bytes));
const withJson = (raw: unknown): PackFile[] => folder().map((f) => (f.name === 'my-walks.json' ? { name: f.name, bytes: new TextEncoder().encode(JSON.stringify(raw)) } : f));

describe('readPack', () => {
  it("makes a registry entry of the generator's kind, labelled as the user's, that can walk and follow paths", async () => {
    const fromFolder = readPack(folder(), ['generator']);
    const fromZip = readPack(await packFiles([{ name: 'my-walks.zip', bytes: new Uint8Array(readFileSync(path.join(DIR, 'my-walks.zip'))) }]), []);
    for (const pack of [fromFolder, fromZip]) {
      expect(pack.info).toMatchObject({ id: 'my-walks', fps: 30, label: 'my-walks (your model)' });
      expect(pack.info.files?.model).toMatch(/^blob:/);
      expect(pack.card.text).toMatch(/^# my-walks/);
      expect(pack.card.thumbnail).toMatch(/^blob:/);
    }
    const registry = new Registry([]);
    expect(registry.add(fromFolder.info)).toBe(true);
    expect(registry.ids('walk')).toEqual(['my-walks']);
    expect(registry.can('my-walks', 'followPath') && registry.can('my-walks', 'liveControl')).toBe(true);
    expect(registry.label('my-walks')).toBe('my-walks (your model)');
    expect(registry.shortName('my-walks')).toBe('my-walks');
    expect(looksLikePack(['my-walks.onnx', 'my-walks.json'])).toBe(true);
    expect(looksLikePack(['walk.bvh'])).toBe(false);
    // A pack trained with --non-commercial (and its --licence) is labelled so; without them, the user's own terms.
    expect(fromFolder.info).toMatchObject({ licence: "your data's own terms", data: 'your folder my-walks (0.2 minutes)' });
    const nc = readPack(withJson({ ...json(), pack: { ...json().pack, licence: 'CC BY-NC 4.0 (Bandai Namco Research)', commercial: false } }), []);
    expect(nc.info).toMatchObject({ licence: 'CC BY-NC 4.0 (Bandai Namco Research)', commercial: false });
    const withNc = new Registry([nc.info]);
    expect(withNc.label('my-walks')).toBe('my-walks (your model) (non-commercial)');
  });

  it('refuses a broken or incompatible pack with a short message', () => {
    const refusal = (files: PackFile[], taken: string[] = []) => {
      try {
        readPack(files, taken);
        return null;
      } catch (e) {
        return (e as Error).message;
      }
    };
    const messages = [
      [refusal(folder(), ['my-walks']), /a model "my-walks" is already listed/],
      [refusal(folder().filter((f) => !f.name.endsWith('.onnx'))), /the pack has no my-walks\.onnx/],
      [refusal(folder().filter((f) => !f.name.endsWith('.json'))), /no model JSON in the pack/],
      [refusal(withJson({ ...json(), kind: 'latent-erd' })), /kind must be "lstm-gmm" \(a locomotion pack\) or "aclstm" \(a dance pack\); got "latent-erd"/],
      [refusal(withJson({ ...json(), kind: undefined })), /kind must be .*; it has none$/],
      // A generator's JSON that calls itself a dance model is checked as one.
      [refusal(withJson({ ...json(), kind: 'aclstm' })), /styles/],
      [refusal(withJson({ ...json(), seeds: [] })), /seeds must be a non-empty array/],
      [refusal(withJson({ ...json(), id: '../../etc' })), /id must be a short name/],
      [refusal([{ name: 'my-walks.json', bytes: new TextEncoder().encode('{ "id": ') }]), /my-walks\.json is not valid JSON/],
    ] as const;
    for (const [message, expected] of messages) {
      expect(message).toMatch(expected);
      expect(message!.length).toBeLessThanOrEqual(300);
    }
  });

  it('makes a dance entry of a dance pack, listed for Dance only, with its style', async () => {
    const fromFolder = readPack(folder('my-dance'), ['aclstm', 'my-walks']);
    const fromZip = readPack(await packFiles([{ name: 'my-dance.zip', bytes: new Uint8Array(readFileSync(path.join(DIR, 'my-dance.zip'))) }]), []);
    for (const pack of [fromFolder, fromZip]) {
      expect(pack.info).toMatchObject({ id: 'my-dance', kind: 'aclstm', fps: 30, styles: ['salsa'], label: 'my-dance (your model)' });
      expect(pack.card.text).toMatch(/^# my-dance/);
    }
    const registry = new Registry([]);
    expect(registry.add(fromFolder.info)).toBe(true);
    expect(registry.ids('dance')).toEqual(['my-dance']);
    expect(registry.ids('walk')).toEqual([]);
    const raw = JSON.parse(new TextDecoder().decode(folder('my-dance').find((f) => f.name === 'my-dance.json')!.bytes));
    const broken = folder('my-dance').map((f) => (f.name === 'my-dance.json' ? { name: f.name, bytes: new TextEncoder().encode(JSON.stringify({ ...raw, seeds: raw.seeds.map((s: { frames: number[][] }) => ({ ...s, frames: s.frames.slice(1) })) })) } : f));
    expect(() => readPack(broken, [])).toThrow(/seeds\[0\]\.frames must hold 10 frames/);
  });
});
