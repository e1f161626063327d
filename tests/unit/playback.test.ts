// The viewer's playback clock (web/viewer/playback.ts): time-based, loops, clamps seeks and speed.
import { describe, expect, it } from 'vitest';
import { MAX_SPEED, MIN_SPEED, Playback } from '../../web/viewer/playback';

describe('Playback', () => {
  it('does not advance while paused', () => {
    const p = new Playback();
    p.reset(121, 120); // one second
    expect(p.duration).toBe(1);
    p.advance(0.5);
    expect(p.frame).toBe(0);
    expect(p.time).toBe(0);
  });

  it('advances by wall time × fps, the same in one step or many', () => {
    const p = new Playback();
    p.reset(121, 120);
    p.playing = true;
    p.advance(0.25);
    expect(p.frame).toBe(30);
    expect(p.frameFloat).toBe(30);
    const q = new Playback();
    q.reset(121, 120);
    q.playing = true;
    for (let i = 0; i < 15; i++) q.advance(0.25 / 15);
    expect(Math.abs(q.frameFloat - 30)).toBeLessThan(1e-9);
  });

  it('scales by speed and loops at the end', () => {
    const p = new Playback();
    p.reset(121, 120);
    p.playing = true;
    p.advance(0.25);
    p.setSpeed(2);
    p.advance(0.25);
    expect(p.frame).toBe(90);
    p.advance(0.25); // 1.25 s → wraps to 0.25 s
    expect(p.frame).toBe(30);
    expect(p.playing).toBe(true);
  });

  it('holds at the end for live data, stops at the end without looping', () => {
    const held = new Playback();
    held.reset(121, 120);
    held.playing = true;
    held.hold = true;
    held.advance(3);
    expect(held.frame).toBe(120);
    expect(held.playing).toBe(true);
    const once = new Playback();
    once.reset(121, 120);
    once.playing = true;
    once.loop = false;
    once.advance(3);
    expect(once.frame).toBe(120);
    expect(once.playing).toBe(false);
  });

  it('clamps speed, and seeks to fractional frames within the clip', () => {
    const p = new Playback();
    p.reset(121, 120);
    expect(p.setSpeed(5)).toBe(MAX_SPEED);
    expect(p.setSpeed(0)).toBe(MIN_SPEED);
    p.seek(1000);
    expect(p.frame).toBe(120);
    p.seek(-3);
    expect(p.frame).toBe(0);
    p.seek(7.5);
    expect(p.frame).toBe(7);
    expect(p.frameFloat).toBe(7.5);
  });

  it('reports its state with the documented keys (docs/api.md state())', () => {
    const p = new Playback();
    p.reset(121, 120);
    p.seek(60);
    p.setSpeed(0.5);
    expect(p.state()).toEqual({ playing: false, frame: 60, time: 0.5, speed: 0.5, frames: 121, fps: 120 });
  });
});
