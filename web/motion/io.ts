// The single import entry point for the UI and the API.
import { MotionFormatError, type Motion } from './types';
import { parseBVH } from './bvh';
import { parseAMC, parseASF } from './asfamc';
import { detectContacts } from './contacts';
import { validateMotion } from './validate';

export { validateMotion } from './validate';

/**
 * Parses a BVH file, or an AMC file with its ASF skeleton, into a checked Motion (metres, y up) with
 * foot contacts attached when the feet can be identified. Bad input raises MotionFormatError.
 */
export function importMotion(text: string, format: 'bvh' | 'amc', asfText?: string): Motion {
  let motion: Motion;
  if (format === 'bvh') {
    motion = parseBVH(text);
  } else if (format === 'amc') {
    if (asfText === undefined || asfText === null) {
      throw new MotionFormatError('amc', 'an AMC motion needs its ASF skeleton file (none given)');
    }
    motion = parseAMC(text, parseASF(asfText));
  } else {
    throw new MotionFormatError('bvh', `unknown format "${String(format)}" (expected "bvh" or "amc")`);
  }
  try {
    motion = validateMotion(motion);
  } catch (e) {
    throw new MotionFormatError(format, (e as Error).message);
  }
  const contacts = detectContacts(motion);
  if (contacts) motion.contacts = contacts;
  return motion;
}
