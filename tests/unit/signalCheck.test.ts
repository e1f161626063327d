// The API's `signal` option (issue 43 #4): what is used of it is required (aborted, addEventListener,
// removeEventListener), and an odd signal-like object cannot leave a call hanging: the call follows it with a
// signal of its own, a listener that cannot be added refuses the call, and forgetting the listener never throws.
import { describe, expect, it } from 'vitest';
import { checkSignal } from '../../web/api/playground';
import { messageOf } from './messageOf';

describe('checkSignal', () => {
  it('passes a left-out signal as none', () => {
    expect(checkSignal(undefined).signal).toBeUndefined();
    expect(checkSignal({}).signal).toBeUndefined();
    expect(checkSignal({ signal: undefined }).signal).toBeUndefined();
  });

  it('refuses an object without what the API uses', () => {
    const noRemove = { aborted: false, addEventListener() {} };
    expect(messageOf(() => checkSignal({ signal: noRemove }))).toMatch(/^signal must be an AbortSignal/);
    expect(messageOf(() => checkSignal({ signal: { aborted: false, removeEventListener() {} } }))).toMatch(/^signal must be an AbortSignal/);
    expect(messageOf(() => checkSignal({ signal: { addEventListener() {}, removeEventListener() {} } }))).toMatch(/^signal must be an AbortSignal/);
    expect(messageOf(() => checkSignal({ signal: 'stop' }))).toBe('signal must be an AbortSignal (an AbortController\'s signal), got "stop"');
    expect(messageOf(() => checkSignal({ signal: null }))).toMatch(/^signal must be an AbortSignal/);
  });

  it('refuses a signal whose addEventListener throws, rather than hanging', () => {
    const odd = { aborted: false, addEventListener() { throw new Error('nope'); }, removeEventListener() {} };
    expect(messageOf(() => checkSignal({ signal: odd }))).toMatch(/^signal must be an AbortSignal.*addEventListener failed \(nope\)/);
  });

  it('follows a real signal with one of its own, and forgets it once released', () => {
    const controller = new AbortController();
    const { signal, release } = checkSignal({ signal: controller.signal });
    expect(signal).toBeInstanceOf(AbortSignal);
    expect(signal).not.toBe(controller.signal);
    expect(signal!.aborted).toBe(false);
    controller.abort('why');
    expect(signal!.aborted).toBe(true);
    expect(signal!.reason).toBe('why');
    release();

    const later = new AbortController();
    const followed = checkSignal({ signal: later.signal });
    followed.release();
    later.abort();
    expect(followed.signal!.aborted).toBe(false);
  });

  it('passes on an already aborted signal as aborted', () => {
    const { signal } = checkSignal({ signal: AbortSignal.abort('gone') });
    expect(signal!.aborted).toBe(true);
    expect(signal!.reason).toBe('gone');
  });

  it('hands the call only its own signal: a signal-like object whose methods fail later cannot break it', () => {
    let listener: (() => void) | null = null;
    const odd = {
      aborted: false,
      get reason(): unknown {
        throw new Error('no reason');
      },
      addEventListener(_type: string, fn: () => void) {
        listener = fn;
      },
      removeEventListener() {
        throw new Error('cannot remove');
      },
    };
    const { signal, release } = checkSignal({ signal: odd });
    expect(() => release()).not.toThrow();
    expect(() => release()).not.toThrow();
    const again = checkSignal({ signal: odd });
    listener!();
    expect(again.signal!.aborted).toBe(true);
    expect(signal!.aborted).toBe(false);
  });
});
