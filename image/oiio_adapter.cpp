// oiio_adapter.cpp - PNG, JPEG, TIFF, HDR, ... through OpenImageIO, behind
// the C interface of oiio_adapter.h.  Built as the module liblf_oiio.so,
// loaded only when an image needs it (image/oiio_loader.c).  Every entry
// point catches all exceptions: C callers cannot unwind through C++ frames.
#include "oiio_adapter.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <vector>


namespace {

const lf_oiio_host *host; // set once by lf_oiio_module_init

// OpenImageIO keeps errors per object and per thread, and complains on
// stderr about any left unretrieved when an object is destroyed, so every
// error is collected (which also clears it) whether or not it is reported.
std::string take_error(const OIIO::ImageInput *in, const OIIO::ImageOutput *out)
{
    std::string msg;
    if (in && in->has_error())
        msg = in->geterror();
    if (out && out->has_error())
        msg = out->geterror();
    std::string global = OIIO::geterror();
    if (msg.empty())
        msg = global;
    if (msg.empty())
        msg = "unknown OpenImageIO error";
    // Some codecs end messages with a newline; ours are single lines.
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r'))
        msg.pop_back();
    for (char &c : msg)
        if (c == '\n')
            c = ' ';
    return msg;
}

bool is_linear_colorspace(const std::string &cs)
{
    std::string lower;
    for (char c : cs)
        lower += (char)std::tolower((unsigned char)c);
    return lower.find("linear") != std::string::npos || lower.rfind("lin_", 0) == 0;
}

int write_bytes(const char *file, const char *name, const std::vector<unsigned char> &bytes, lf_error *err)
{
    FILE *f = std::fopen(file, "wb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, std::strerror(errno));
    bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0;
    int e = errno;
    ok = std::fclose(f) == 0 && ok;
    if (!ok)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, std::strerror(e ? e : errno));
    return LF_OK;
}

int write_impl(const char *file, const char *name, int width, int height, int channels, lf_oiio_pixel_type type,
               const void *pixels, lf_error *err)
{
    auto out = OIIO::ImageOutput::create(file);
    if (!out)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot write '%s': %s", name,
                            take_error(nullptr, nullptr).c_str());
    OIIO::TypeDesc td = type == LF_OIIO_FLOAT ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    OIIO::ImageSpec spec(width, height, channels, td);
    if (type == LF_OIIO_UINT8)
        spec.attribute("oiio:ColorSpace", "sRGB");
    else
        spec.attribute("oiio:ColorSpace", "Linear");
    if (channels == 2 || channels == 4)
        spec.alpha_channel = channels - 1;
    // Pixels are stored exactly as given: OpenImageIO must not divide colour
    // by alpha on the way out (nor multiply on the way in, see read_impl).
    spec.attribute("oiio:UnassociatedAlpha", 1);
    // Encoded into memory when the format can, then written here: libjpeg's
    // default error handler ends the process on a failed fwrite (a full disk),
    // which killed the process without a message of ours or any cleanup.
    std::vector<unsigned char> encoded;
    OIIO::Filesystem::IOVecOutput vec(encoded);
    bool in_memory = out->supports("ioproxy") && out->set_ioproxy(&vec);
    if (!out->open(file, spec))
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, take_error(nullptr, out.get()).c_str());
    bool ok = out->write_image(td, pixels);
    ok = out->close() && ok; // close flushes: its failure is a failed write
    if (!ok)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, take_error(nullptr, out.get()).c_str());
    take_error(nullptr, out.get());
    return in_memory ? write_bytes(file, name, encoded, err) : LF_OK;
}

int read_impl(const char *file, const char *name, lf_image *img, lf_oiio_read_info *info, lf_error *err)
{
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(file, &config);
    if (!in)
        return lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': %s", name, take_error(nullptr, nullptr).c_str());
    const OIIO::ImageSpec &spec = in->spec();
    if (spec.deep) {
        take_error(in.get(), nullptr);
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot read '%s': deep images are not supported", name);
    }
    // Volumes would need depth; one slice is not the image the user meant.
    if (spec.depth > 1) {
        take_error(in.get(), nullptr);
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot read '%s': volume images are not supported", name);
    }
    // Checked before any pixel is allocated: the header may be lying.
    int rc = host->check_size(spec.width, spec.height, spec.nchannels, name, LF_ERR_PARSE, err);
    if (rc) {
        take_error(in.get(), nullptr);
        return rc;
    }
    rc = host->alloc(img, spec.width, spec.height, spec.nchannels, err);
    if (rc) {
        take_error(in.get(), nullptr);
        return rc;
    }
    // Some codecs (libtiff) deliver a short file as success plus an error
    // message, so a pending error also counts as failure.
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img->data) || in->has_error()) {
        std::string msg = take_error(in.get(), nullptr);
        host->free_image(img);
        return lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': %s", name, msg.c_str());
    }
    info->alpha_channel = spec.alpha_channel >= 0 && spec.alpha_channel < spec.nchannels ? spec.alpha_channel : -1;
    info->srgb_encoded = !spec.format.is_floating_point() &&
                         !is_linear_colorspace(spec.get_string_attribute("oiio:ColorSpace"));
    in->close();
    take_error(in.get(), nullptr);
    return LF_OK;
}

int module_write(const char *file, const char *name, int width, int height, int channels,
                             lf_oiio_pixel_type type, const void *pixels, lf_error *err)
{
    try {
        return write_impl(file, name, width, height, channels, type, pixels, err);
    } catch (const std::bad_alloc &) {
        return lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", name);
    } catch (const std::exception &e) {
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot write '%s': OpenImageIO: %s", name, e.what());
    } catch (...) {
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot write '%s': unknown OpenImageIO exception", name);
    }
}

int module_read(const char *file, const char *name, lf_image *img, lf_oiio_read_info *info,
                            lf_error *err)
{
    try {
        return read_impl(file, name, img, info, err);
    } catch (const std::bad_alloc &) {
        host->free_image(img);
        return lf_error_set(err, LF_ERR_NOMEM, "cannot read '%s': out of memory", name);
    } catch (const std::exception &e) {
        host->free_image(img);
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot read '%s': OpenImageIO: %s", name, e.what());
    } catch (...) {
        host->free_image(img);
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot read '%s': unknown OpenImageIO exception", name);
    }
}

} // namespace

extern "C" __attribute__((visibility("default"))) const lf_oiio_module *lf_oiio_module_init(const lf_oiio_host *h)
{
    static const lf_oiio_module module = {LF_OIIO_MODULE_ABI, module_write, module_read};
    if (!h || h->abi != LF_OIIO_MODULE_ABI)
        return nullptr;
    host = h;
    return &module;
}
