// A model posted to the daemon (POST /api/uploads, streamed to disk by the server, the
// engineer's session cookie going with it), then submitted over the WebSocket with the plan
// settings the form holds. The server checks both: its message is what the person sees.
import type { Rpc } from "./rpc";
import type { Job } from "./types";

// Only the extension matters to the server (the model's format); the job keeps the real name.
function plainName(name: string): string {
  const cleaned = name.replace(/[^A-Za-z0-9._-]/g, "_").replace(/^\.+/, "");
  return cleaned.length > 0 ? cleaned.slice(-200) : "model.stl";
}

// XMLHttpRequest rather than fetch: it reports the upload's progress.
function post(file: File, onProgress: (fraction: number) => void): Promise<string> {
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open("POST", `/api/uploads?name=${plainName(file.name)}`);
    xhr.setRequestHeader("Content-Type", "application/octet-stream");
    xhr.upload.onprogress = (e) => {
      if (e.lengthComputable && e.total > 0) onProgress(e.loaded / e.total);
    };
    xhr.onerror = () => reject(new Error("the upload was cut off"));
    xhr.onload = () => {
      let reply: { upload?: string; error?: string } = {};
      try {
        reply = JSON.parse(xhr.responseText);
      } catch {
        // a proxy's page, or nothing: the status says enough
      }
      if (xhr.status === 200 && reply.upload) resolve(reply.upload);
      else reject(new Error(reply.error ?? `the upload was refused (HTTP ${xhr.status})`));
    };
    xhr.send(file);
  });
}

export async function uploadAndSubmit(
  rpc: Rpc,
  file: File,
  settings: Record<string, unknown>,
  onProgress: (fraction: number) => void,
): Promise<Job> {
  const upload = await post(file, onProgress);
  try {
    return await rpc.call<Job>("job.submit", { upload, name: file.name, settings });
  } catch (e) {
    await rpc.call("upload.cancel", { upload }).catch(() => undefined);
    throw e;
  }
}
