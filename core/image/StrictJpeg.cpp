#include "core/image/StrictJpeg.h"

#include <csetjmp>
#include <cstdio>

#include <jpeglib.h>

namespace mirage {

namespace {

struct StrictErrorManager {
    jpeg_error_mgr pub;  // first member: libjpeg casts the pointer back
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

extern "C" void strictErrorExit(j_common_ptr cinfo) {
    auto* err = reinterpret_cast<StrictErrorManager*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, err->message);
    std::longjmp(err->jump, 1);
}

// Level -1 is a warning about corrupt data; treated like an error. Trace messages (>= 1) are
// ignored.
extern "C" void strictEmitMessage(j_common_ptr cinfo, int level) {
    if (level < 0) strictErrorExit(cinfo);
}

// The libjpeg part: no C++ object with a destructor lives across setjmp/longjmp here.
bool decodeInto(const uint8_t* data, size_t size, cv::Mat& out, char* message) {
    jpeg_decompress_struct cinfo;
    StrictErrorManager err;
    cinfo.err = jpeg_std_error(&err.pub);
    err.pub.error_exit = strictErrorExit;
    err.pub.emit_message = strictEmitMessage;
    err.message[0] = '\0';
    if (setjmp(err.jump)) {
        std::snprintf(message, JMSG_LENGTH_MAX, "%s", err.message);
        jpeg_destroy_decompress(&cinfo);
        return false;
    }
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    if (cinfo.image_width < 1 || cinfo.image_height < 1 || cinfo.image_width > kMaxJpegSide ||
        cinfo.image_height > kMaxJpegSide) {
        std::snprintf(message, JMSG_LENGTH_MAX, "image size %ux%u outside 1..%d", cinfo.image_width,
                      cinfo.image_height, kMaxJpegSide);
        jpeg_destroy_decompress(&cinfo);
        return false;
    }
    cinfo.out_color_space = JCS_EXT_BGR;
    jpeg_start_decompress(&cinfo);
    out.create(int(cinfo.output_height), int(cinfo.output_width), CV_8UC3);
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = out.ptr<uchar>(int(cinfo.output_scanline));
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);  // reads to EOI: warns about data that is cut or left over
    jpeg_destroy_decompress(&cinfo);
    return true;
}

}  // namespace

cv::Mat decodeJpegStrict(const uint8_t* data, size_t size, std::string* problem) {
    if (data == nullptr || size < 4) {
        if (problem) *problem = "no JPEG data";
        return {};
    }
    cv::Mat out;
    char message[JMSG_LENGTH_MAX] = {0};
    if (!decodeInto(data, size, out, message)) {
        if (problem) *problem = std::string("corrupt JPEG (") + message + ")";
        return {};
    }
    return out;
}

}  // namespace mirage
