// The page's part of importing dropped or picked files (read and parsed in the import worker:
// runtime/import/importClient.ts, runtime/import/motionFiles.ts): the progress shown while a large import runs.
import type { ImportProgress, ProgressListener } from '../runtime/import/motionFiles';
import { $ } from './dom';

/** Imports of at least this many bytes (the files together, as given) show their progress. */
export const LARGE_IMPORT_BYTES = 1_000_000;

const STAGE_NAMES: Record<ImportProgress['stage'], string> = { read: 'Reading', decompress: 'Decompressing', parse: 'Parsing' };

/**
 * The "Reading 07_04.bvh… 40 %" indicator beside the model status: shown while at least one large import
 * runs; `data-stage` is the latest stage reported ("read", "decompress", "parse").
 */
export class ImportIndicator {
  private readonly element = $('import-status');
  private readonly label = $('import-stage');
  private readonly bar = $<HTMLProgressElement>('import-progress');
  private running = 0;

  /** Runs an import of `bytes` bytes, showing the progress it reports when it is large. */
  async track<T>(bytes: number, run: (onProgress?: ProgressListener) => Promise<T>): Promise<T> {
    if (bytes < LARGE_IMPORT_BYTES) return run();
    this.running++;
    this.show({ stage: 'read', file: '', fraction: 0 });
    this.element.hidden = false;
    try {
      return await run((progress) => this.show(progress));
    } finally {
      if (--this.running === 0) this.element.hidden = true;
    }
  }

  private show({ stage, file, fraction }: ImportProgress): void {
    this.element.dataset.stage = stage;
    this.label.textContent = `${STAGE_NAMES[stage]}${file ? ` ${file}` : ''}…${fraction === undefined ? '' : ` ${Math.round(fraction * 100)} %`}`;
    if (fraction === undefined) this.bar.removeAttribute('value'); // indeterminate: parsing reports no share
    else this.bar.value = fraction;
  }
}
