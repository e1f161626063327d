// Test helper: BVH text for a generated skeleton of any shape and size (deep chains, wide fans), for the
// tests of hierarchies the importer must reject or read without recursion.

/**
 * A BVH file whose joints j0 … j(n-1) have the given parents (joint 0 the root, parent -1; every parent
 * before its child). Every non-root bone has OFFSET 0 1 0 and three rotation channels, the root six
 * channels; no End Sites. The motion is `frames` frames of zeros at 30 fps.
 */
export function generatedBVH(parents: readonly number[], frames = 1): string {
  const children: number[][] = parents.map(() => []);
  parents.forEach((p, j) => {
    if (p >= 0) children[p].push(j);
  });
  const out = ['HIERARCHY'];
  // Depth first without recursion: a stack of joints still to write and the braces that close them.
  const stack: Array<number | '}'> = [0];
  while (stack.length > 0) {
    const item = stack.pop()!;
    if (item === '}') {
      out.push('}');
      continue;
    }
    const root = item === 0;
    out.push(root ? 'ROOT j0' : `JOINT j${item}`, '{', root ? 'OFFSET 0 0 0' : 'OFFSET 0 1 0');
    out.push(root ? 'CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation' : 'CHANNELS 3 Zrotation Yrotation Xrotation');
    stack.push('}');
    for (let k = children[item].length - 1; k >= 0; k--) stack.push(children[item][k]);
  }
  const values = 6 + 3 * (parents.length - 1);
  const frameLine = Array(values).fill('0').join(' ');
  out.push('MOTION', `Frames: ${frames}`, 'Frame Time: 0.0333333');
  for (let f = 0; f < frames; f++) out.push(frameLine);
  return out.join('\n') + '\n';
}

