// acLSTM family: the dance model's raw step and end-to-end generate (1 and 2 threads), and Dance mode (the
// acLSTM streaming beside the display).
import { liveModeBenchmark, liveModeSummary, modelBenchmark } from './common.mjs';

const DANCE_CLIENT = { module: '/runtime/aclstm/danceClient.ts', name: 'DanceClient', options: { model: 'aclstm' } };

export const BENCHMARKS = [
  ...[1, 2].map((threads) => ({
    name: `aclstm-single-t${threads}`,
    description: `acLSTM, one dance (batch 1): 2000 raw steps, and generate 3000 frames (steps + decode + skeleton fit), ${threads} thread(s) requested — target ≥ 600 frames/s`,
    run: (ctx) =>
      modelBenchmark(ctx, { client: DANCE_CLIENT, threads, batch: 1, steps: 2000, generate: { style: 'salsa', seed: 0, frames: 3000 } }).then((r) => ({
        ...r,
        target_frames_per_s: 600,
      })),
    summary: (r) =>
      `${r.generate_frames_per_s} frames/s end to end (target ≥ 600), raw steps ${r.steps_per_s}/s, ${r.ms_per_call} ms/call,` +
      ` ${r.threads} thread(s)${r.isolated ? '' : ' (not isolated)'}`,
  })),
  {
    name: 'dance-mode',
    description: 'Dance mode streaming acLSTM (30 fps model) (default threads), skeleton fit and pose-change plot, default quality — target 60 fps',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-dance', 'dance-status'),
    summary: liveModeSummary,
  },
];
