// Reads a leader file off the page's thread: the text, the BVH reader, the check and the
// reduction to 17 joints (web/ui/leaderfile.ts) all run here, so a big file does not stop the
// dance while it is read. One worker per file (web/ui/dropzone.ts starts and ends it).

import { DuetError } from './errors';
import { displayName, leaderMotionFromText } from './leaderfile';
import type { FromLeaderWorker } from './dropzone';

const post = (message: FromLeaderWorker, transfer: Transferable[] = []) => self.postMessage(message, { transfer });

self.onmessage = async (event: MessageEvent<File>) => {
  const file = event.data;
  try {
    let text: string;
    try {
      text = await file.text();
    } catch (error) {
      throw new DuetError(`Cannot read ${displayName(file.name)}`, (error as Error)?.message || 'The browser could not read the file.');
    }
    const motion = leaderMotionFromText(text, file.name);
    post({ motion }, [motion.positions.buffer, motion.rotations.buffer, motion.offsets.buffer]);
  } catch (error) {
    // Anything else (out of memory on a huge file) is a message too, never a silent worker.
    const detail = error instanceof DuetError ? error.detail : error instanceof Error ? error.message : String(error);
    const title = error instanceof DuetError ? error.title : `Cannot dance ${displayName(file.name)}`;
    post({ error: { title, detail } });
  }
};
