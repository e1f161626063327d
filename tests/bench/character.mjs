// Character family (issue 40): Random walk drawn as the project's mannequin, against the stick figure, at both
// qualities. The goal is 60 fps with a 30k-vertex character; the mannequin's vertex count is reported.
import { liveModeBenchmark, liveModeSummary } from './common.mjs';

const summary = (r) => `${liveModeSummary(r)}, look ${r.look}, ${r.character_vertices} character vertices`;

export const BENCHMARKS = [
  {
    name: 'random-walk-character',
    description: 'Random walk drawn as the mannequin (the default look), default quality (software GL: matcap shading, blob shadow) — target 60 fps',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status', undefined, '?look=character'),
    summary,
  },
  {
    name: 'random-walk-character-high',
    description: 'Random walk drawn as the mannequin, ?quality=high (lit, shadow map, MSAA) — target 60 fps with a GPU',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status', undefined, '?look=character&quality=high'),
    summary,
  },
  {
    name: 'random-walk-skeleton',
    description: 'Random walk drawn as the stick figure (?look=skeleton), default quality: the baseline for the two above',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status', undefined, '?look=skeleton'),
    summary,
  },
];
