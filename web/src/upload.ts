// A model sent over the WebSocket in pieces (upload.begin / chunk, docs/api.md), then submitted
// with the plan settings the form holds. The server checks the settings: its message is shown.
import type { Rpc } from "./rpc";
import type { Job } from "./types";

const kChunkBytes = 384 * 1024;  // under the server's 512 KiB decoded, and its 1 MiB request line

function base64(bytes: Uint8Array): string {
  let text = "";
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

export async function uploadAndSubmit(
  rpc: Rpc,
  file: File,
  settings: Record<string, unknown>,
  onProgress: (fraction: number) => void,
): Promise<Job> {
  const data = new Uint8Array(await file.arrayBuffer());
  const { upload } = await rpc.call<{ upload: string }>("upload.begin", { name: file.name, size: data.length });
  try {
    for (let offset = 0; offset < data.length; offset += kChunkBytes) {
      await rpc.call("upload.chunk", { upload, offset, data: base64(data.subarray(offset, offset + kChunkBytes)) });
      onProgress(Math.min(1, (offset + kChunkBytes) / data.length));
    }
    return await rpc.call<Job>("job.submit", { upload, name: file.name, settings });
  } catch (e) {
    await rpc.call("upload.cancel", { upload }).catch(() => undefined);
    throw e;
  }
}
